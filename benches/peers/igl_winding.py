"""The peer of `cargo bench --bench fgm -- --peer`: a scan's signed distance as a libigl user
makes it — the inside by libigl's fast winding numbers for oriented point clouds (Barill et al.
2018, `igl.fast_winding_number`, second-order expansion, β = 2), each point's area π ρ² / 8
(ρ: the distance to its 8th neighbour, SciPy's cKDTree), the magnitude the distance to the
nearest point (cKDTree) — at the same voxels as latvox's grid: every voxel of its narrow band,
and a random sample of the voxels beyond it (the winding number alone: only their sign is
compared, as latvox keeps only a sign there). The peer is given the scan's exact normals
(latvox estimates its own from the points).

Both are compared with the torus's exact signed distance (ring radius R, tube radius r, about
the z axis through the origin): in the band (|d| < 2 voxels) the mean, 99th percentile and
largest error; everywhere the voxels of the wrong sign (where |d| > half a voxel).

usage: python3 igl_winding.py SCAN.xyz(x y z nx ny nz) LATVOX.npz R r [DEEP]
LATVOX.npz: latvox's sdf grid as vdb_dense.py writes it. Prints JSON."""
import json
import sys
import time

import igl
import numpy as np
from scipy.spatial import cKDTree

scan, dense, big, small = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4])
deep = int(sys.argv[5]) if len(sys.argv) > 5 else 200_000
data = np.loadtxt(scan)
P, N = np.ascontiguousarray(data[:, :3]), np.ascontiguousarray(data[:, 3:6])
g = np.load(dense)
values, origin, h, bg = g["values"], g["origin"], float(g["voxel"]), float(g["background"])
band = np.argwhere(np.abs(values) < 0.999 * bg)
rest = np.argwhere(np.abs(values) >= 0.999 * bg)
rng = np.random.default_rng(7)
rest = rest[rng.choice(len(rest), size=min(deep, len(rest)), replace=False)]
idx = np.concatenate([band, rest])
Q = origin + idx * h
latvox = values[idx[:, 0], idx[:, 1], idx[:, 2]].astype(np.float64)
in_band = np.arange(len(idx)) < len(band)

t0 = time.perf_counter()
tree = cKDTree(P)
rho = tree.query(P, k=9, workers=-1)[0][:, 8]
A = np.pi * rho * rho / 8.0
t1 = time.perf_counter()
w = igl.fast_winding_number(P, N, A, Q, 2, 2.0)
t2 = time.perf_counter()
# The distance at the band's voxels (beyond it latvox keeps only a sign, and so does the peer).
u = np.ones(len(Q))
u[in_band] = tree.query(Q[in_band], k=1, workers=-1)[0]
peer = np.where(w > 0.5, -u, u)
t3 = time.perf_counter()

ring = np.hypot(Q[:, 0], Q[:, 1]) - big
exact = np.hypot(ring, Q[:, 2]) - small


def measure(v, band_only):
    near = in_band & (np.abs(exact) < 2.0 * h)
    err = np.abs(v - exact)[near]
    decided = np.abs(exact) > 0.5 * h
    wrong = decided & (np.sign(v) != np.sign(exact))
    return {
        "band_mean": float(err.mean()),
        "band_p99": float(np.percentile(err, 99)),
        "band_max": float(err.max()),
        "within_half_voxel": float((err < 0.5 * h).mean()),
        "wrong_sign": int(wrong.sum()),
        "wrong_sign_in_band": int((wrong & in_band).sum()),
    }


print(json.dumps({
    "points": len(P),
    "voxel": h,
    "band_voxels": int(len(band)),
    "beyond_sampled": int(len(rest)),
    "peer_seconds": {"areas": t1 - t0, "winding": t2 - t1, "distance": t3 - t2, "total": t3 - t0},
    "latvox": measure(latvox, True),
    "peer": measure(peer, True),
}))
