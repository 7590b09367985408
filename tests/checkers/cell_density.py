"""Per-cell density of a lattice part, measured by manifold3d (an independent mesh library).

Usage: cell_density.py MESH ORIGIN_X,Y,Z CELL_X,Y,Z SIZE_X,Y,Z

The mesh (read by trimesh, its vertices merged) must be a manifold solid for manifold3d. It is
cut into slabs along x, each slab along y, each of those along z, at the cells' faces (the box
cut into cells from its lower corner, partial cells at the far sides), and each piece's volume
taken. Prints JSON: {"status", "components" (connected shells), "solids" (shells enclosing
positive volume: a void inside a skin is a shell of its own), "volume",
"cells": [[i, j, k, fraction], ...]}.
"""
import json
import math
import sys

import manifold3d as m3
import numpy as np
import trimesh


def triple(s):
    return [float(v) for v in s.split(",")]


def main():
    path, origin, cell, size = sys.argv[1], triple(sys.argv[2]), triple(sys.argv[3]), triple(sys.argv[4])
    mesh = trimesh.load(path, force="mesh", process=True)
    solid = m3.Manifold(
        m3.Mesh(
            vert_properties=np.asarray(mesh.vertices, dtype=np.float32),
            tri_verts=np.asarray(mesh.faces, dtype=np.uint32),
        )
    )
    status = str(solid.status())
    counts = [max(1, math.ceil(size[a] / cell[a] - 1e-9)) for a in range(3)]

    def cut(pieces, axis):
        """Each (index, piece) split at the cell faces along `axis`."""
        out = []
        for index, piece in pieces:
            rest = piece
            for k in range(counts[axis]):
                plane = origin[axis] + (k + 1) * cell[axis]
                normal = [0.0, 0.0, 0.0]
                normal[axis] = 1.0
                if k + 1 < counts[axis]:
                    above, below = rest.split_by_plane(normal, plane)
                else:
                    above, below = None, rest
                out.append((index + [k], below))
                rest = above
        return out

    pieces = cut(cut(cut([([], solid)], 0), 1), 2)
    cells = []
    for (i, j, k), piece in pieces:
        box = [min(cell[a], origin[a] + size[a] - (origin[a] + [i, j, k][a] * cell[a])) for a in range(3)]
        cells.append([i, j, k, piece.volume() / (box[0] * box[1] * box[2])])
    print(json.dumps({
        "status": status,
        "components": len(solid.decompose()),
        # Shells enclosing solid (a void's shell, inside-out, encloses negative volume).
        "solids": sum(1 for c in solid.decompose() if c.volume() > 0),
        "volume": solid.volume(),
        "cells": cells,
    }))


main()
