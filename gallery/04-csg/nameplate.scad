// A name plate: raised text on a rounded plate (OpenSCAD's text(), Liberation Sans).
$fn = 48;
hull() {
    for (x = [4, 76], y = [4, 21]) translate([x, y, 0]) cylinder(r = 4, h = 3);
}
translate([40, 12.5, 2.5]) linear_extrude(height = 2.5)
    text("implicitvox", size = 9, halign = "center", valign = "center");
