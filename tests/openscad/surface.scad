// Heightmaps as OpenSCAD 2021.01 builds them: a .dat table (centred, cut by a
// cylinder) and a PNG image (scaled down; and inverted, which OpenSCAD computes
// as 1 - pixel: negative heights).
difference() {
    scale([2, 2, 1]) surface(file = "heights.dat", center = true);
    translate([0, 0, -5]) cylinder(r = 2.5, h = 20, $fn = 16);
}
translate([14, -6, 0]) scale([1, 1, 0.1]) surface(file = "heights.png");
translate([-26, -6, 0]) scale([1, 1, 0.02]) surface(file = "heights.png", invert = true);
