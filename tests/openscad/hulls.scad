// hull, minkowski and resize, as OpenSCAD 2021.01 renders them (exact on polytopes)
hull() {
    cube(4);
    translate([10, 0, 0]) sphere(3, $fn = 16);
    translate([0, 8, 6]) cylinder(r = 2, h = 3, $fn = 12);
}
translate([0, 20, 0]) linear_extrude(5) hull() {
    circle(3, $fn = 20);
    translate([8, 0]) square(3);
}
translate([0, 34, 0]) linear_extrude(2) minkowski() {
    square([6, 3]);
    circle(1, $fn = 12);
}
translate([20, 0, 0]) minkowski() {
    union() { cube([6, 2, 2]); translate([0, 4, 0]) cube([2, 6, 2]); }
    sphere(1.5, $fn = 10);
}
translate([20, 20, 0]) minkowski() {
    cube([6, 6, 2]);
    cylinder(r = 2, h = 1, $fn = 8);
}
translate([-20, 0, 0]) resize([12, 0, 0], auto = [false, true, false])
    union() { cube([4, 2, 3]); translate([2, 2, 0]) cube(2); }
translate([-20, 20, 0]) resize(newsize = [6, 6, 9]) hull() {
    cube(2);
    translate([3, 3, 3]) cube(1);
}
