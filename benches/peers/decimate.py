"""The uniform mesh decimated as a user of a mesh-only simplifier does it: fast-simplification
(PyPI; Fast-Quadric-Mesh-Simplification, quadric error edge collapses) to a triangle count.

Usage: python3 decimate.py IN.stl TRIANGLES OUT.stl

Prints the seconds the decimation took (reading and writing not counted).
"""
import sys
import time
import numpy as np
import trimesh
import fast_simplification

mesh = trimesh.load(sys.argv[1], process=True)
target = int(sys.argv[2])
points = np.asarray(mesh.vertices, dtype=np.float64)
faces = np.asarray(mesh.faces, dtype=np.int64)
t = time.perf_counter()
p, f = fast_simplification.simplify(points, faces, target_reduction=1.0 - target / len(faces))
seconds = time.perf_counter() - t
trimesh.Trimesh(p, f, process=False).export(sys.argv[3])
print(f"{seconds:.3f}")
