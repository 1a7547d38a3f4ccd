"""How many items each hot loop hands numpy per call: every batch size, in one place.

A batch is large enough that numpy's per-call overhead vanishes and small
enough that its working arrays stay in cache (or, for the frontier, that the
subdivision's stack stays bounded). Each was measured on its own loop; they
differ because the working sets per item differ. Changing one changes no
result (the batch and its pieces give the same bits), only speed and memory.
"""
from __future__ import annotations

__all__ = ["POINTS", "BOXES", "FRONTIER", "NORMALS", "MORTON", "TRIANGLE_PAIRS",
           "LINF_POINTS", "LINF_MESH_POINTS", "SETTLE_BOXES"]

#: points per pass of the point evaluator (a few arrays per tape register)
POINTS = 1 << 16
#: boxes per pass of the interval evaluator (a tape's few dozen arrays stay in cache)
BOXES = 1 << 16
#: octants per chunk of the subdivision frontier (children evaluated 8 at a time)
FRONTIER = 1 << 17
#: voxels whose normals are computed per pass (a gradient tape: 4 arrays per register)
NORMALS = 1 << 18
#: rows per Morton encode/decode pass (ten shift-and-mask passes stay in cache)
MORTON = 1 << 16
#: (node, triangle) pairs per step of the mesh subdivision
TRIANGLE_PAIRS = 1 << 16
#: points per block of the convex polytope's max-norm distance (a face table per point)
LINF_POINTS = 1 << 14
#: points per block of the triangle mesh's max-norm distance (a hierarchy walk per point)
LINF_MESH_POINTS = 1 << 15
#: unknown boxes a csg classifier settles at once (each splits into up to 64 sub-boxes)
SETTLE_BOXES = 2048
