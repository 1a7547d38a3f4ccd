// A mesh imported from another fixture's STL (OpenSCAD's import()), mirrored and
// drilled, beside a cube: the imported mesh takes part in the booleans.
difference() {
    union() {
        mirror([1, 0, 0]) import("bracket.stl", convexity = 4);
        translate([-45, 0, 0]) cube([6, 20, 10]);
    }
    translate([-20, 5, -1]) cylinder(h = 20, r = 2.5, $fn = 20);
}
