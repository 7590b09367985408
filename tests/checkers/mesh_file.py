"""Reads mesh files with independent libraries and reports, as JSON per file, the triangle count
enclosed volume and area: STL, OBJ and PLY by trimesh (loaded as written, nothing merged or
repaired), 3MF by lib3mf (the 3MF Consortium's reference library), its volume summed here.

usage: python3 mesh_file.py FILE... > out.json
"""
import json
import sys

import numpy as np


def measures(v, f):
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    volume = float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)
    area = float(np.linalg.norm(np.cross(b - a, c - a), axis=1).sum() / 2.0)
    return {"triangles": len(f), "volume": volume, "area": area}


def read_3mf(path):
    import lib3mf

    w = lib3mf.get_wrapper()
    m = w.CreateModel()
    m.QueryReader("3mf").ReadFromFile(path)
    out = {"triangles": 0, "volume": 0.0, "area": 0.0}
    it = m.GetMeshObjects()
    while it.MoveNext():
        o = it.GetCurrentMeshObject()
        v = np.array([p.Coordinates[0:3] for p in o.GetVertices()], dtype=float)
        f = np.array([t.Indices[0:3] for t in o.GetTriangleIndices()], dtype=np.int64)
        if len(f):
            for k, x in measures(v, f).items():
                out[k] += x
    return out


def read_trimesh(path):
    import trimesh

    m = trimesh.load(path, process=False, force="mesh")
    v = np.asarray(m.vertices, dtype=float)
    f = np.asarray(m.faces, dtype=np.int64)
    return measures(v, f)


out = {}
for path in sys.argv[1:]:
    out[path] = read_3mf(path) if path.lower().endswith(".3mf") else read_trimesh(path)
json.dump(out, sys.stdout)
