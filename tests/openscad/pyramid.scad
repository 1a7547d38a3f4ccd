// A polyhedron (square pyramid) intersected with a sphere, on a rendered base.
intersection() {
    polyhedron(points = [[-10, -10, 0], [10, -10, 0], [10, 10, 0], [-10, 10, 0], [0, 0, 15]],
               faces = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4], [1, 0, 3], [2, 1, 3]]);
    sphere(r = 13, $fa = 6, $fs = 1);
}
render() translate([0, 0, -3]) cube([24, 24, 3], center = true);
