// Twisted and scaled extrusions that give no `slices`: OpenSCAD computes them
// (get_helix_slices, get_conical_helix_slices, get_diagonal_slices in its calc.cc)
// and splits side quads whose diagonals tie by the twist's direction.
union() {
    linear_extrude(height = 10, twist = 90) translate([3, 0]) square(5);
    translate([20, 0, 0]) linear_extrude(height = 10, twist = -60, scale = [2, 0.5])
        square(5, center = true);
    translate([0, 20, 0]) linear_extrude(height = 20, twist = 120, scale = 0.3) circle(4, $fn = 7);
    translate([20, 20, 0]) linear_extrude(height = 10, scale = [2, 0.5]) square(5);
}
