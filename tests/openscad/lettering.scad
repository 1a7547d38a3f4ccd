// OpenSCAD 2021.01's text: the default font (Liberation Sans) with kerning
// ("AV"), holes and islands ("o", "i"), a bold face centred both ways, curves
// from $fn, wide spacing, and text offset and engraved into a plate.
linear_extrude(height = 2) text("AVoid ji", size = 10);
translate([0, -16, 0]) linear_extrude(height = 3)
    text("Bg&8", size = 8, font = "Liberation Sans:style=Bold", halign = "center",
         valign = "center", $fn = 16);
translate([0, -32, 0]) linear_extrude(height = 1.5) text("e%Q", size = 6, spacing = 1.4);
difference() {
    translate([30, -40, 0]) cube([30, 14, 2]);
    translate([45, -33, 1]) linear_extrude(height = 2)
        offset(r = 0.3) text("SC", size = 7, halign = "center", valign = "center");
}
