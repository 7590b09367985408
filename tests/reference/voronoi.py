"""An independent check of a Voronoi foam: SciPy's Voronoi diagram (Qhull) of the same seeds,
points sampled on its edges (net) or faces (sheet) well inside the box, and the seeds, each
classified against the written STL by its generalised winding number (Jacobson et al. 2013,
the Van Oosterom–Strackee solid angle of every triangle), in NumPy.

usage: voronoi.py SEEDS.csv PART.stl net|sheet|pores LEVEL MARGIN X0 Y0 Z0 X1 Y1 Z1 [PERIOD [POINTS]]
  pores: the centroids of faces of inradius LEVEL or more (where a sheet's pores are);
  LEVEL: the strut radius or wall thickness (pores: the least inradius); MARGIN: how far inside the box points are taken;
  PERIOD: the seeds are one cell of this edge from the box's lower corner, repeated through the
  box and a cell round it (a periodic foam); POINTS: how many member points to test (150; half
  as many seeds).
Prints JSON: the member points and how many lie inside, the seeds and how many lie outside.
"""
import json
import sys

import numpy as np
from scipy.spatial import Voronoi


def read_stl(path):
    data = open(path, "rb").read()
    n = int.from_bytes(data[80:84], "little")
    rec = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    return np.frombuffer(data, dtype=rec, count=n, offset=84)["v"].astype(np.float64)


def segment_distance(p, a, b):
    ab = b - a
    t = np.clip(np.dot(p - a, ab) / max(np.dot(ab, ab), 1e-300), 0.0, 1.0)
    return float(np.linalg.norm(p - (a + t * ab)))


def winding(tris, points):
    # The corners' coordinates as nine contiguous arrays: plain element-wise arithmetic on them
    # is several times faster than row-wise products on (n, 3) arrays.
    t = [np.ascontiguousarray(tris[:, i, k]) for i in range(3) for k in range(3)]
    out = []
    for p in points:
        ax, ay, az = t[0] - p[0], t[1] - p[1], t[2] - p[2]
        bx, by, bz = t[3] - p[0], t[4] - p[1], t[5] - p[2]
        cx, cy, cz = t[6] - p[0], t[7] - p[1], t[8] - p[2]
        la = np.sqrt(ax * ax + ay * ay + az * az)
        lb = np.sqrt(bx * bx + by * by + bz * bz)
        lc = np.sqrt(cx * cx + cy * cy + cz * cz)
        det = ax * (by * cz - bz * cy) + ay * (bz * cx - bx * cz) + az * (bx * cy - by * cx)
        div = (la * lb * lc + (ax * bx + ay * by + az * bz) * lc
               + (bx * cx + by * cy + bz * cz) * la + (cx * ax + cy * ay + cz * az) * lb)
        out.append(np.arctan2(det, div).sum() / (2 * np.pi))
    return np.array(out)


def main():
    seeds_path, stl, structure, level, margin = sys.argv[1:6]
    level, margin = float(level), float(margin)
    box = np.array([float(x) for x in sys.argv[6:12]]).reshape(2, 3)
    seeds = np.loadtxt(seeds_path, delimiter=",", skiprows=1)
    if len(sys.argv) > 12:
        period = float(sys.argv[12])
        cells = [int(np.ceil((box[1][k] - box[0][k]) / period)) for k in range(3)]
        shifts = [np.array([i, j, k]) * period
                  for i in range(-1, cells[0] + 1)
                  for j in range(-1, cells[1] + 1)
                  for k in range(-1, cells[2] + 1)]
        seeds = np.concatenate([seeds + s for s in shifts])
    vor = Voronoi(seeds)
    inner = (box[0] + margin, box[1] - margin)

    def within(p):
        return bool(np.all(p >= inner[0]) and np.all(p <= inner[1]))

    members = []
    for ridge in vor.ridge_vertices:
        if -1 in ridge:
            continue
        poly = vor.vertices[ridge]
        if structure == "net":
            for a, b in zip(poly, np.roll(poly, -1, axis=0)):
                if np.linalg.norm(b - a) < 4 * margin:
                    continue
                for t in (0.3, 0.5, 0.7):
                    members.append(a + t * (b - a))
        elif structure == "sheet":
            centre = poly.mean(axis=0)
            members.append(centre)
            members.extend(centre + 0.5 * (v - centre) for v in poly)
        else:
            # "pores": the centroids of the faces whose inradius (from the centroid) is at
            # least LEVEL, where the pores are.
            centre = poly.mean(axis=0)
            inradius = min(segment_distance(centre, a, b)
                           for a, b in zip(poly, np.roll(poly, -1, axis=0)))
            if inradius >= level:
                members.append(centre)
    members = [p for p in members if within(p)]
    # A hundred and fifty points spread over the box are plenty: keep the test quick.
    n = int(sys.argv[13]) if len(sys.argv) > 13 else 150
    members = np.array(members[:: max(1, len(members) // n)][:n])
    far = np.array([s for s in seeds if within(s)])
    far = far[:: max(1, len(far) // (n // 2))]
    tris = read_stl(stl)
    wm = winding(tris, members)
    wf = winding(tris, far)
    print(json.dumps({
        "member_points": int(len(members)),
        "members_inside": int((wm > 0.5).sum()),
        "seeds": int(len(far)),
        "seeds_outside": int((wf < 0.5).sum()),
    }))


main()
