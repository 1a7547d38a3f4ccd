// OpenSCAD 2021.01's offset (Clipper): round (r), sharp (delta) and chamfered joins,
// outward and inward, of 2D booleans, transforms and a polygon with a hole.
linear_extrude(height = 3) offset(r = 2, $fn = 24) {
    square([10, 6]);
    translate([12, 3]) rotate(30) square([4, 4], center = true);
}
translate([0, 14, 0]) linear_extrude(height = 3) offset(delta = 1.5)
    polygon(points = [[0, 0], [12, 0], [12, 8], [6, 3], [0, 8]]);
translate([20, 14, 0]) linear_extrude(height = 3) offset(delta = 1.5, chamfer = true)
    polygon(points = [[0, 0], [12, 0], [12, 8], [6, 3], [0, 8]]);
translate([20, 0, 0]) linear_extrude(height = 3) offset(r = -1, $fn = 16) difference() {
    square([12, 10]);
    translate([6, 5]) circle(r = 3, $fn = 20);
}
translate([36, 0, 0]) linear_extrude(height = 3) offset(r = 1, $fa = 6, $fs = 0.5)
    polygon(points = [[0, 0], [10, 0], [10, 10], [0, 10], [3, 3], [7, 3], [7, 7], [3, 7]],
            paths = [[0, 1, 2, 3], [4, 5, 6, 7]]);
translate([36, 16, 0]) rotate_extrude($fn = 24) translate([2, 0]) offset(r = 0.8, $fn = 12)
    intersection() { square([4, 6]); translate([2, 3]) circle(r = 2.5, $fn = 16); }
