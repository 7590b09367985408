"""Per-cell density of a lattice tube (cells wrapped around an axis), measured by manifold3d.

Usage: tube_cells.py MESH CX,CY,CZ BORE NT,NR,NZ AR,AZ

The tube's axis is parallel to z through (CX, CY); its lower end is at CZ; NT cells around
(starting at the angle -pi, the -x side), NR through the wall from the radius BORE, NZ along the
axis; cells AR through the wall and AZ along it. The mesh (read by trimesh, vertices merged) is
cut by manifold3d into slabs along z, each slab into wedges by the two planes through the axis
at the cell's angles, and (with several cells through the wall) each wedge by cylinders (1024-gons)
at the cells' radii; each piece's volume over its cell's (an annular sector). Prints JSON:
{"status", "components", "volume", "cells": [[around, through, along, fraction], ...]}.
"""
import json
import math
import sys

import manifold3d as m3
import numpy as np
import trimesh


def numbers(s, kind=float):
    return [kind(v) for v in s.split(",")]


def main():
    path = sys.argv[1]
    c, bore = numbers(sys.argv[2]), float(sys.argv[3])
    nt, nr, nz = numbers(sys.argv[4], int)
    ar, az = numbers(sys.argv[5])
    mesh = trimesh.load(path, force="mesh", process=True)
    solid = m3.Manifold(
        m3.Mesh(
            vert_properties=np.asarray(mesh.vertices, dtype=np.float32),
            tri_verts=np.asarray(mesh.faces, dtype=np.uint32),
        )
    )
    outer = bore + nr * ar
    cells = []
    for l in range(nz):
        z0 = c[2] + l * az
        slab = solid.trim_by_plane((0.0, 0.0, 1.0), z0).trim_by_plane((0.0, 0.0, -1.0), -(z0 + az))
        for k in range(nt):
            a0 = -math.pi + 2 * math.pi * k / nt
            a1 = a0 + 2 * math.pi / nt
            n0 = (-math.sin(a0), math.cos(a0), 0.0)
            n1 = (math.sin(a1), -math.cos(a1), 0.0)
            wedge = slab.trim_by_plane(n0, n0[0] * c[0] + n0[1] * c[1]).trim_by_plane(
                n1, n1[0] * c[0] + n1[1] * c[1]
            )
            for j in range(nr):
                r0, r1 = bore + j * ar, bore + (j + 1) * ar
                piece = wedge
                cylinder = lambda r: m3.Manifold.cylinder(az + 2, r, r, 1024).translate((c[0], c[1], z0 - 1))
                if j < nr - 1:
                    piece = piece ^ cylinder(r1)
                if j > 0:
                    piece = piece - cylinder(r0)
                sector = 0.5 * (a1 - a0) * (r1 * r1 - r0 * r0) * az
                cells.append([k, j, l, piece.volume() / sector])
    print(
        json.dumps(
            {
                "status": str(solid.status()),
                "components": len(solid.decompose()),
                "volume": solid.volume(),
                "tube": math.pi * (outer * outer - bore * bore) * nz * az,
                "cells": cells,
            }
        )
    )


if __name__ == "__main__":
    main()
