// OpenSCAD 2021.01's projection: sections by z = 0 through booleans (exact), and
// shadows of meshes and polytopes, extruded again.
linear_extrude(height = 3) projection(cut = true) translate([0, 0, -4]) difference() {
    cube([20, 14, 10]);
    translate([10, 7, 4]) sphere(r = 5, $fn = 18);
    translate([3, 3, -1]) rotate([0, 0, 20]) cube([4, 4, 12]);
}
translate([26, 0, 0]) linear_extrude(height = 2) projection()
    rotate([35, 20, 0]) union() {
        cube([8, 6, 4], center = true);
        translate([5, 0, 0]) cylinder(r = 3, h = 8, $fn = 12);
    }
translate([0, 20, 0]) linear_extrude(height = 2) projection()
    rotate([90, 0, 0]) import("bracket.stl");
translate([40, 20, 0]) linear_extrude(height = 2) projection(cut = true)
    translate([0, 0, -2.5]) rotate([0, 0, 45]) import("bracket.stl");
