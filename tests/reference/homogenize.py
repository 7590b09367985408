"""An independent transcription of voxel homogenisation (Andreassen & Andreasen 2014; Dong,
Tang & Zhao 2019) in NumPy/SciPy: a strut cell voxelised by its voxel centres, trilinear
hexahedra integrated by Gauss quadrature, the stiffness assembled as a sparse matrix on the
periodic grid, one node fixed, and the six unit-strain load cases solved by a direct sparse
factorisation (no iterative solver, no multigrid).

usage: homogenize.py CELL RADIUS N LAMBDA MU   (CELL: sc or bcc, unit cube)
prints JSON: {"density": ρ, "C": 6×6 in Voigt order xx, yy, zz, yz, xz, xy}
"""
import itertools
import json
import sys

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

cell, radius, n, lam, mu = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])

corners = np.array(list(itertools.product([0.0, 1.0], repeat=3)))
if cell == "sc":
    segs = [(np.zeros(3), np.eye(3)[a]) for a in range(3)]
elif cell == "bcc":
    segs = [(c, np.full(3, 0.5)) for c in corners]
else:
    raise SystemExit("cell must be sc or bcc")

# Voxel centres, and their distance to every strut axis of the cell and its 26 neighbours.
h = 1.0 / n
c = (np.arange(n) + 0.5) * h
X, Y, Z = np.meshgrid(c, c, c, indexing="ij")
P = np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1)
dist = np.full(len(P), np.inf)
for shift in itertools.product([-1.0, 0.0, 1.0], repeat=3):
    for a, b in segs:
        a2, b2 = a + shift, b + shift
        d = b2 - a2
        t = np.clip(((P - a2) @ d) / (d @ d), 0.0, 1.0)
        q = a2 + t[:, None] * d
        dist = np.minimum(dist, np.linalg.norm(P - q, axis=1))
solid = (dist <= radius).reshape(n, n, n)  # [i, j, k]

# Element matrix: nodes in the order (x, y, z) = bits of the node number, 2×2×2 Gauss points.
D = np.zeros((6, 6))
D[:3, :3] = lam
D[:3, :3] += 2 * mu * np.eye(3)
D[3:, 3:] = mu * np.eye(3)
signs = np.array([[(a >> k) & 1 for k in range(3)] for a in range(8)]) * 2 - 1
ke = np.zeros((24, 24))
g = 1 / np.sqrt(3)
for xi in itertools.product([-g, g], repeat=3):
    xi = np.array(xi)
    B = np.zeros((6, 24))
    for a in range(8):
        s = signs[a]
        nn = 0.5 * (1 + s * xi)
        dn = np.array([s[k] * np.prod([nn[l] for l in range(3) if l != k]) / h for k in range(3)])
        B[0, 3 * a] = dn[0]
        B[1, 3 * a + 1] = dn[1]
        B[2, 3 * a + 2] = dn[2]
        B[3, 3 * a + 1], B[3, 3 * a + 2] = dn[2], dn[1]
        B[4, 3 * a], B[4, 3 * a + 2] = dn[2], dn[0]
        B[5, 3 * a], B[5, 3 * a + 1] = dn[1], dn[0]
    ke += B.T @ D @ B * (h ** 3 / 8)

# Unit-strain nodal displacements of one element.
chi0 = np.zeros((6, 24))
local = (signs + 1) / 2 * h
for case in range(6):
    e = np.zeros((3, 3))
    if case < 3:
        e[case, case] = 1
    else:
        i, j = [(1, 2), (0, 2), (0, 1)][case - 3]
        e[i, j] = e[j, i] = 0.5
    chi0[case] = (local @ e.T).ravel()

# Periodic assembly over the solid voxels.
node = lambda i, j, k: (i % n) + n * ((j % n) + n * (k % n))
elems = np.argwhere(solid)
edof = np.zeros((len(elems), 24), dtype=np.int64)
for a in range(8):
    off = (signs[a] + 1) // 2
    nd = node(elems[:, 0] + off[0], elems[:, 1] + off[1], elems[:, 2] + off[2])
    for r in range(3):
        edof[:, 3 * a + r] = 3 * nd + r
ndof = 3 * n ** 3
rows = np.repeat(edof, 24, axis=1).ravel()
cols = np.tile(edof, (1, 24)).ravel()
K = sp.coo_matrix((np.tile(ke.ravel(), len(elems)), (rows, cols)), shape=(ndof, ndof)).tocsc()
F = np.zeros((ndof, 6))
for case in range(6):
    np.add.at(F[:, case], edof.ravel(), np.tile(ke @ chi0[case], len(elems)))
active = np.unique(edof)
free = active[3:]  # one node fixed against rigid translation
chi = np.zeros((ndof, 6))
solve = spla.factorized(K[free][:, free].tocsc())
for case in range(6):
    chi[free, case] = solve(F[free, case])

C = np.zeros((6, 6))
for i in range(6):
    di = chi0[i][None, :] - chi[edof, i]
    for j in range(6):
        dj = chi0[j][None, :] - chi[edof, j]
        C[i, j] = np.einsum("ea,ab,eb->", di, ke, dj)
C /= 1.0
print(json.dumps({"density": float(solid.mean()), "C": C.tolist()}))
