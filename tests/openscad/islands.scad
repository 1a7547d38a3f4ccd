// polygon(paths = ...) filled even-odd, as OpenSCAD fills it: an outline, a hole in
// it and an island in the hole (the dot of an "i" inside an "o"), and a second outline
// beside them; straight and twisted.
module islands() {
    polygon(points = [[0, 0], [12, 0], [12, 12], [0, 12],
                      [2, 2], [10, 2], [10, 10], [2, 10],
                      [4, 4], [8, 4], [8, 8], [4, 8],
                      [14, 0], [18, 0], [18, 6], [14, 6]],
            paths = [[0, 1, 2, 3], [4, 5, 6, 7], [8, 9, 10, 11], [12, 13, 14, 15]]);
}
linear_extrude(height = 4) islands();
translate([0, 0, 6]) linear_extrude(height = 6, twist = 30) islands();
