"""Reads a level-set .vdb with OpenVDB's own Python module (Debian's python3-openvdb) and reports,
as JSON, its grids' names and classes, the voxel size, and the volume inside the zero iso-surface
(OpenVDB's volumeToMesh by convertToPolygons, the polygons' enclosed volume summed here).

usage: /usr/bin/python3 vdb_level_set.py FILE.vdb > out.json
"""
import json
import sys

import numpy as np
import pyopenvdb as vdb

path = sys.argv[1]
grids = [{"name": g.name, "class": str(g.gridClass)} for g in vdb.readAllGridMetadata(path)]
sdf = vdb.read(path, "sdf")
points, triangles, quads = sdf.convertToPolygons(0.0)
faces = [np.asarray(triangles, dtype=np.int64).reshape(-1, 3)]
quads = np.asarray(quads, dtype=np.int64).reshape(-1, 4)
faces += [quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]]
f = np.concatenate(faces)
v = np.asarray(points, dtype=float)
a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
volume = abs(float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0))
json.dump(
    {
        "grids": grids,
        "voxel": list(sdf.transform.voxelSize()),
        "volume": volume,
        "active": sdf.activeVoxelCount(),
    },
    sys.stdout,
)
