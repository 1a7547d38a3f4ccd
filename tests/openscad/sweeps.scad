// rotate_extrude as OpenSCAD 2021.01 facets it: full sweeps of odd sector counts
// (it starts them on the -x axis), partial sweeps (one of a single sector), a
// clockwise one, a profile on the axis.
rotate_extrude($fn = 15) translate([6, 0]) square([2, 3]);
translate([20, 0, 0]) rotate_extrude($fn = 11) polygon([[0, 0], [5, 0], [3, 4], [0, 4]]);
translate([0, 20, 0]) rotate_extrude(angle = 250, $fn = 15) translate([4, 0]) circle(r = 2, $fn = 6);
translate([20, 20, 0]) rotate_extrude(angle = -120, $fn = 9) translate([3, 0]) square([3, 2]);
translate([10, 10, 0]) rotate_extrude(angle = 30, $fn = 9) translate([3, 0]) square([3, 2]);
