// A knob: a revolved profile (rotate_extrude of a polygon and a circle), knurled by
// subtracting cylinders, with a mirrored pointer.
$fn = 40;
difference() {
    rotate_extrude()
        union() {
            polygon([[0, 0], [12, 0], [12, 6], [9, 10], [0, 10]]);
            translate([9, 10]) circle(r = 2);
        }
    for (a = [0 : 45 : 359]) rotate([0, 0, a]) translate([13, 0, -1]) cylinder(h = 8, r = 2);
    translate([0, 0, -1]) cylinder(h = 6, r = 3);
}
color("red") mirror([1, 0, 0]) translate([2, -1, 10]) cube([8, 2, 2]);
