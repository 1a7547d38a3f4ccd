// A rounded frame: the Minkowski sum of a difference (a slotted frame, not convex)
// and a small octahedron, which bevels every edge.
minkowski() {
    difference() {
        cube([40, 30, 6], center = true);
        cube([28, 18, 10], center = true);
        translate([0, 0, 3]) cube([50, 4, 4], center = true);
    }
    scale([1.5, 1.5, 1]) rotate([45, 35.26, 0]) cube(1.6, center = true);
}
