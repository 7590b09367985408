"""Per-cell density of a lattice part, measured by manifold3d (an independent mesh library).

Usage: cell_density.py MESH ORIGIN_X,Y,Z CELL_X,Y,Z SIZE_X,Y,Z [AXIS:E0,E1,...]

(AXIS:E0,E1,... gives the cells' faces along one axis, from the box's lower face to its upper
one, for cells whose size varies along it.)

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
    # The cells' faces per axis (partial cells at the far sides), or those given for one axis.
    edges = [
        [origin[a] + min(k * cell[a], size[a]) for k in range(counts[a] + 1)] for a in range(3)
    ]
    if len(sys.argv) > 5:
        axis, given = sys.argv[5].split(":")
        edges["xyz".index(axis)] = triple(given)

    def cut(pieces, axis):
        """Each (index, piece) split at the cell faces along `axis`."""
        out = []
        normal = [0.0, 0.0, 0.0]
        normal[axis] = 1.0
        planes = edges[axis][1:-1]
        for index, piece in pieces:
            rest = piece
            for k, plane in enumerate(planes):
                above, below = rest.split_by_plane(normal, plane)
                out.append((index + [k], below))
                rest = above
            out.append((index + [len(planes)], rest))
        return out

    pieces = cut(cut(cut([([], solid)], 0), 1), 2)
    cells = []
    for (i, j, k), piece in pieces:
        box = [edges[a][n + 1] - edges[a][n] for a, n in enumerate((i, j, k))]
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
