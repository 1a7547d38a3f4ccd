// A DXF drawing (drawing.dxf, written by drawing_dxf.py with ezdxf) imported as
// OpenSCAD 2021.01 imports it: layers, origin, scale, arcs in $fn/$fa/$fs fragments,
// extruded straight, scaled and revolved.
linear_extrude(height = 6) import("drawing.dxf", layer = "plate");
translate([0, 0, 10]) linear_extrude(height = 4, scale = 0.8)
    import("drawing.dxf", layer = "tab", $fn = 24);
translate([0, -20, 0]) linear_extrude(height = 3)
    import("drawing.dxf", layer = "teeth", origin = [40, 0], scale = 2);
translate([60, 0, 0]) rotate_extrude($fn = 32)
    import("drawing.dxf", layer = "tab", origin = [-2, 28]);
