// A twisted, tapering vase: linear_extrude with twist and scale, hollowed.
difference() {
    linear_extrude(height = 30, twist = 90, scale = 0.6, slices = 24)
        square([20, 20], center = true);
    translate([0, 0, 3]) linear_extrude(height = 30, twist = 90, scale = 0.5, slices = 24)
        circle(r = 6, $fn = 30);
}
