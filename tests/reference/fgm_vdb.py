"""Reads an FGM .vdb with OpenVDB's own Python module (Debian's python3-openvdb) and reports, as
JSON, what the tests check independently of latvox: the grids' names, classes and voxel sizes,
and for every active voxel of the material grids its world position, distance value and
fractions.

usage: /usr/bin/python3 fgm_vdb.py FILE.vdb MATERIAL[,MATERIAL...] > out.json
"""
import json
import sys

import pyopenvdb as vdb

path, materials = sys.argv[1], sys.argv[2].split(",")
meta = vdb.readAllGridMetadata(path)
grids = [
    {"name": g.name, "class": str(g.gridClass), "voxel": list(g.transform.voxelSize())}
    for g in meta
]
distance = vdb.read(path, "distance")
mats = [vdb.read(path, m) for m in materials]
dacc = distance.getConstAccessor()
maccs = [m.getConstAccessor() for m in mats]
voxels = []
for item in mats[0].citerOnValues():
    lo, hi = item.min, item.max
    for i in range(lo[0], hi[0] + 1):
        for j in range(lo[1], hi[1] + 1):
            for k in range(lo[2], hi[2] + 1):
                c = (i, j, k)
                w = mats[0].transform.indexToWorld(c)
                voxels.append([list(w), dacc.getValue(c), [a.getValue(c) for a in maccs]])
sdf = vdb.read(path, "sdf")
json.dump(
    {
        "grids": grids,
        "voxels": voxels,
        "sdf_active": sdf.activeVoxelCount(),
        "material_active": [m.activeVoxelCount() for m in mats],
    },
    sys.stdout,
)
