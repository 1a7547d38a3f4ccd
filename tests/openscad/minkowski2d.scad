// 2D Minkowski sums with operands that are not convex
linear_extrude(height = 2) minkowski() {
    difference() { square(10); translate([3, 3]) square(4); }
    circle(r = 1, $fn = 8);
}
translate([15, 0, 0]) linear_extrude(height = 3) minkowski() {
    polygon([[0, 0], [6, 0], [6, 2], [2, 2], [2, 6], [0, 6]]);
    polygon([[0, 0], [2, 1], [0, 2], [1, 1]]);
}
translate([0, 15, 0]) linear_extrude(height = 1.5) minkowski() {
    polygon([[0, 0], [5, 0], [5, 5], [2.5, 1.7], [0, 5]]);
    square([1, 0.5]);
    rotate(30) square([0.7, 0.3], center = true);
}
translate([15, 15, 0]) linear_extrude(height = 2, twist = 0) minkowski() {
    union() { square([8, 1]); translate([7, 0]) square([1, 8]); translate([20, 20]) square(1); }
    polygon([[0, 0], [1.3, 0.2], [0.4, 0.9], [0.6, 0.3]]);
}
