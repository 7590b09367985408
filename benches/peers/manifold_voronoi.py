"""A Voronoi strut foam as a user of a mesh-boolean library builds it: SciPy's Voronoi diagram
(Qhull) of the seeds, each edge a capsule — a cylinder and a sphere at each end — from
manifold3d (PyPI; the Manifold library, exact and robust mesh booleans), unioned in one batch,
intersected with the box, written as binary STL.

Usage: python3 manifold_voronoi.py SEEDS.csv RADIUS SIZE OUT.stl [SEGMENTS]

The geometry is latvox's `voronoi --seeds-in SEEDS.csv --radius RADIUS --size SIZE`: the box
[0, SIZE]³, every Voronoi edge that reaches into it. SEGMENTS (16) polygon sides per circle.
"""
import sys

import manifold3d as m3d
import numpy as np
from scipy.spatial import Voronoi

seeds = np.loadtxt(sys.argv[1], delimiter=",", skiprows=1)
r = float(sys.argv[2])
size = float(sys.argv[3])
out = sys.argv[4]
seg = int(sys.argv[5]) if len(sys.argv) > 5 else 16

vor = Voronoi(seeds)
edges = set()
for ridge in vor.ridge_vertices:
    if -1 in ridge:
        continue
    for a, b in zip(ridge, ridge[1:] + ridge[:1]):
        edges.add((min(a, b), max(a, b)))
lo, hi = -r, size + r
used = set()
parts = []
for a, b in edges:
    p, q = vor.vertices[a], vor.vertices[b]
    if np.any(np.minimum(p, q) > hi) or np.any(np.maximum(p, q) < lo):
        continue
    d = q - p
    h = float(np.linalg.norm(d))
    if h < 1e-9:
        continue
    z = d / h
    t = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(t, z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    parts.append(m3d.Manifold.cylinder(h, r, r, seg).transform(np.column_stack([x, y, z, p])))
    used.update((a, b))
sphere = m3d.Manifold.sphere(r, seg)
parts.extend(sphere.translate(vor.vertices[v]) for v in used)
foam = m3d.Manifold.batch_boolean(parts, m3d.OpType.Add) ^ m3d.Manifold.cube([size] * 3)
mesh = foam.to_mesh()
v = np.asarray(mesh.vert_properties, dtype=np.float32)[:, :3]
t = np.asarray(mesh.tri_verts, dtype=np.int64)
tri = v[t]
n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
rec = np.zeros(len(t), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
rec["n"] = n
rec["v"] = tri
with open(out, "wb") as f:
    f.write(b"\0" * 80)
    f.write(np.uint32(len(t)).tobytes())
    f.write(rec.tobytes())
print(len(t), foam.volume())
