"""The peer of `cargo bench --bench slice`: trimesh's section_multiplane on the same mesh and the
same planes as latvox. Usage: trimesh_slice.py MESH Z0 DZ N — planes at Z0 + k·DZ, k < N,
normal +Z. Prints JSON: seconds to load, seconds to section, closed loops found."""
import json
import sys
import time

import numpy as np
import trimesh

path, z0, dz, n = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4])
t0 = time.perf_counter()
mesh = trimesh.load(path, force="mesh")
t1 = time.perf_counter()
heights = z0 + dz * np.arange(n)
sections = mesh.section_multiplane(plane_origin=[0.0, 0.0, 0.0], plane_normal=[0.0, 0.0, 1.0], heights=heights)
t2 = time.perf_counter()
# Loops are assembled lazily by trimesh: asking for them is part of the work latvox does.
loops = sum(len(s.discrete) for s in sections if s is not None)
t3 = time.perf_counter()
print(json.dumps({"load_s": t1 - t0, "section_s": t2 - t1, "loops_s": t3 - t2, "loops": loops}))
