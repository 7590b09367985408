"""Per-cell density of a lattice on a cubed-sphere shell, measured by manifold3d.

Usage: sphere_cells.py MESH CX,CY,CZ BORE N,K A

The shell is centred at (CX, CY, CZ), from the radius BORE out through K cells of A mm; at the
bore each of a cube's six faces holds N x N cells. The test's own map takes a point p to cell
coordinates: with d = p - c, m = max |d_i|, h = N/2 + (|d| - BORE)/A,
u_i = h * (4/pi) * atan(d_i / m) + N/2, so that the shell is the image of the cubic shell
[-K, N+K]^3 minus (0, N)^3. The mesh (read by trimesh, vertices merged) is warped into cell
coordinates, cut there by manifold3d into unit cells (slabs, then columns, then cubes), and
each piece warped back (its cut faces refined first, so they follow the curved cell faces);
its volume over its cell's (the unit cube refined and warped back the same way). Prints JSON:
{"status", "components", "volume", "shell", "cells": [[i, j, k, fraction, cell volume], ...]}.
"""
import json
import math
import sys

import manifold3d as m3
import numpy as np
import trimesh


def main():
    path = sys.argv[1]
    c = np.array([float(v) for v in sys.argv[2].split(",")])
    bore = float(sys.argv[3])
    n, k = [int(v) for v in sys.argv[4].split(",")]
    a = float(sys.argv[5])
    half = n / 2.0

    def forward(p):
        p = np.asarray(p, dtype=np.float64)
        d = p - c
        r = np.linalg.norm(d, axis=1)
        mx = np.abs(d).max(axis=1)
        h = half + (r - bore) / a
        return h[:, None] * (4 / math.pi) * np.arctan(d / mx[:, None]) + half

    def inverse(u):
        v = np.asarray(u, dtype=np.float64) - half
        h = np.abs(v).max(axis=1)
        r = bore + (h - half) * a
        t = np.tan(math.pi / 4 * v / h[:, None])
        return c + r[:, None] * t / np.linalg.norm(t, axis=1)[:, None]

    mesh = trimesh.load(path, force="mesh", process=True)
    solid = m3.Manifold(
        m3.Mesh(
            vert_properties=np.asarray(mesh.vertices, dtype=np.float32),
            tri_verts=np.asarray(mesh.faces, dtype=np.uint32),
        )
    )
    warped = solid.warp_batch(forward)
    lo, hi = -k, n + k
    step = 1.0 / 24

    def back(piece):
        return piece.refine_to_length(step).warp_batch(inverse).volume()

    cells = []
    for i in range(lo, hi):
        slab = warped.trim_by_plane((1, 0, 0), i).trim_by_plane((-1, 0, 0), -(i + 1))
        for j in range(lo, hi):
            column = slab.trim_by_plane((0, 1, 0), j).trim_by_plane((0, -1, 0), -(j + 1))
            for l in range(lo, hi):
                if 0 <= i < n and 0 <= j < n and 0 <= l < n:
                    continue
                piece = column.trim_by_plane((0, 0, 1), l).trim_by_plane((0, 0, -1), -(l + 1))
                cube = m3.Manifold.cube((1, 1, 1)).translate((i, j, l))
                volume = back(cube)
                cells.append([i, j, l, back(piece) / volume, volume])
    outer = bore + k * a
    print(
        json.dumps(
            {
                "status": str(solid.status()),
                "components": len(solid.decompose()),
                "volume": solid.volume(),
                "shell": 4 / 3 * math.pi * (outer**3 - bore**3),
                "cells": cells,
            }
        )
    )


if __name__ == "__main__":
    main()
