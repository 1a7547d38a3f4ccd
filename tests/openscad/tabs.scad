// A plate with a polygon hole (paths), a rotated partial revolve, and a group.
group() {
    linear_extrude(height = 3)
        polygon(points = [[0, 0], [30, 0], [30, 20], [0, 20], [10, 5], [20, 5], [15, 15]],
                paths = [[0, 1, 2, 3], [4, 5, 6]]);
    // overlapping the plate by 0.5, as OpenSCAD models should (no coincident faces)
    translate([15, 10, 2.5]) rotate_extrude(angle = 270, $fn = 36)
        translate([6, 0]) square([2, 5.5]);
    multmatrix([[1, 0.3, 0, 35], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) cube([5, 20, 6]);
}
