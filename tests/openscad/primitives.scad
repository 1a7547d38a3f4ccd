// Default facets ($fa = 12, $fs = 2), cones, centred cylinders, intersection, a scaled
// extrusion with a vector scale, and a mirrored group.
union() {
    sphere(r = 8);
    translate([20, 0, 0]) cylinder(h = 16, r1 = 6, r2 = 2, center = true);
    translate([0, 20, 0]) intersection() {
        cube(12, center = true);
        sphere(r = 7.5, $fn = 20);
    }
    translate([20, 20, -6]) linear_extrude(height = 12, scale = [1, 0.4], slices = 6)
        circle(r = 5);
    mirror([0, 1, 0]) translate([0, 12, -4]) cube([6, 6, 8]);
}
