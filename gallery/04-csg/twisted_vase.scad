// A twisted vase: a star, extruded with a twist and a taper, hollowed by a smaller
// star twisted alike (turned to match where it starts, 3 mm up).
module star(r1, r2, n = 7) {
    polygon([for (i = [0:2 * n - 1]) let(a = 180 * i / n, r = i % 2 ? r2 : r1)
             [r * cos(a), r * sin(a)]]);
}
difference() {
    linear_extrude(height = 40, twist = 120, scale = 1.4, slices = 60) star(15, 10);
    translate([0, 0, 3]) rotate([0, 0, -9]) scale(1 + 0.4 * 3 / 40)
        linear_extrude(height = 40, twist = 120, scale = 1.4, slices = 60) star(12, 7.5);
}
