// Constructs of issue 51, each checked against OpenSCAD 2021.01's own STL.
// A 2D child of a 3D boolean is ignored (a warning), not an endless drill.
difference() { cube(10); circle(r = 6); }
// resize with auto: every auto axis takes the factor of the largest new size.
translate([20, 0, 0]) resize([6, 0, 0], auto = [1, 1, 1]) cube(9);
// An intersection with an empty extrusion is empty.
translate([20, 20, 0]) intersection() { cube(10); linear_extrude(height = 0) square(5); }
// A hull skips an empty child (here an empty intersection) and hulls the rest.
translate([0, 20, 0]) hull() {
    cube([1, 1, 1]);
    translate([4, 0, 0]) cube([1, 1, 1]);
    intersection() { cube(1); translate([5, 5, 5]) cube(1); }
}
// An extrusion scaled to 0 along one axis: its top slice is split along the other
// diagonal (OpenSCAD's add_slice), or the wedge would differ from OpenSCAD's.
translate([40, 0, 0]) linear_extrude(height = 10, scale = [1, 0], slices = 1)
    polygon([[10, 0], [0, 5], [0, -5]]);
translate([40, 20, 0]) linear_extrude(height = 10, scale = [1, 0], slices = 2)
    polygon([[10, 0], [0, 5], [0, -5]]);
// Minkowski sums of pieces that are not convex: a difference (a tube with a notch)
// and a non-convex polyhedron (a box with a dent in its top), each with a box.
translate([0, 40, 0]) minkowski() {
    difference() {
        cube(10);
        translate([3, 3, -1]) cube([4, 4, 12]);
        translate([-1, 4, 6]) cube([12, 2, 5]);
    }
    cube(1, center = true);
}
translate([20, 40, 0]) minkowski() {
    polyhedron(points = [[0, 10, 10], [10, 10, 10], [10, 0, 10], [0, 0, 10], [0, 0, 0],
                         [10, 0, 0], [10, 10, 0], [0, 10, 0], [5, 5, 4]],
               faces = [[4, 5, 6, 7], [3, 2, 5, 4], [2, 1, 6, 5], [1, 0, 7, 6], [0, 3, 4, 7],
                        [0, 1, 8], [1, 2, 8], [2, 3, 8], [3, 0, 8]]);
    rotate([0, 0, 30]) cube([1, 2, 1], center = true);
}
