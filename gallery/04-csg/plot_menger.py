"""
A Menger sponge: a cube minus 273 bars
======================================

The level-3 sponge, ``max(cube, -min(bar_1, ..., bar_273))``, a CSG model of many
parts with sharp edges everywhere. Each octant is evaluated with the expression
pruned to the bars that can matter there (:mod:`implicitvox.eval.pruning`): near
any voxel a few dozen of the 646 instructions remain, and the voxels are the same,
bit for bit, as with the whole expression (``prune=False``).
"""
# %%
from implicitvox.gallery import RESOLUTION, out

import implicitvox as iv
from implicitvox.expr.examples import menger

# %%
vox = iv.voxelize(menger(3), RESOLUTION, normals=True)
print(vox.render(out("menger.png"), title=f"Menger sponge (level 3), {vox.count:,} surface "
                 f"voxels, {vox.metadata['tapes_built']} pruned tapes"), vox.count)
