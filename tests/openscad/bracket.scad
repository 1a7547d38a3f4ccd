// A mounting bracket: a plate minus two bolt holes, with a scaled, rotated rib
// (nested multmatrix with a non-uniform scale).
difference() {
    union() {
        cube([40, 20, 4]);
        translate([20, 10, 4]) scale([1, 0.5, 2]) rotate([0, 0, 30]) translate([-8, -2, 0])
            cube([16, 4, 5]);
    }
    translate([8, 10, -1]) cylinder(h = 20, r = 3, $fn = 24);
    translate([32, 10, -1]) cylinder(h = 20, r = 3, $fn = 24);
}
