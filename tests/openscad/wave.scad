// A twisted extrusion with an uneven scale of a square with a triangular hole
// (OpenSCAD turns each section, then scales it).
linear_extrude(height = 10, twist = 60, slices = 10, scale = [0.8, 0.5])
    difference() {
        square([8, 8], center = true);
        polygon(points = [[-2, -2], [2, -2], [0, 2]]);
    }
