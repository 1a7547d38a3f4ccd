// OpenSCAD 2021.01's projection() of booleans: the shadow of a difference's and an
// intersection's result (OpenSCAD computes the boolean, then projects it), extruded.
linear_extrude(height = 2) projection() rotate([30, 20, 0]) difference() {
    sphere(r = 10, $fn = 16);
    cylinder(h = 25, r1 = 5, r2 = 2.5, center = true, $fn = 12);
    rotate([90, 0, 0]) cylinder(h = 25, r1 = 5, r2 = 2.5, center = true, $fn = 12);
}
translate([24, 0, 0]) linear_extrude(height = 3) projection() rotate([0, 50, 10])
    intersection() {
        cube([12, 12, 4], center = true);
        rotate([0, 0, 45]) cube([12, 12, 12], center = true);
        rotate([70, 0, 0]) cylinder(r = 6, h = 20, center = true, $fn = 10);
    }
