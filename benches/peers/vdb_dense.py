"""Reads a level set from a .vdb with OpenVDB's own Python module (Debian's python3-openvdb) into
a dense array over its active voxels' bounding box, for a peer to compare with.

usage: /usr/bin/python3 vdb_dense.py FILE.vdb GRID OUT.npz
OUT.npz: `values` (float32, x slowest), `origin` (the world position of its first voxel),
`voxel` (the edge, mm), `background`."""
import sys

import numpy as np
import pyopenvdb as vdb

path, name, out = sys.argv[1], sys.argv[2], sys.argv[3]
grid = vdb.read(path, name)
lo, hi = grid.evalActiveVoxelBoundingBox()
shape = tuple(hi[a] - lo[a] + 1 for a in range(3))
values = np.zeros(shape, dtype=np.float32)
grid.copyToArray(values, ijk=lo)
np.savez(
    out,
    values=values,
    origin=np.array(grid.transform.indexToWorld(lo)),
    voxel=np.array(grid.transform.voxelSize()[0]),
    background=np.array(grid.background),
)
