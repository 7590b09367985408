"""Per-cell density of a lattice whose cells are sized by a field, measured by manifold3d (an
independent mesh library) on cells computed here from the field's own formula.

Usage: sized_cells.py MESH ORIGIN_X,Y,Z SIZE_X,Y,Z NX,NY,NZ radial:BASE,SLOPE,CX,CY

The field is the cell size s = BASE + SLOPE·√((x−CX)² + (y−CY)²) mm. Along each axis a, the
cell coordinate is N_a·Φ(p)/Φ(upper face), Φ the integral of 1/s along the line through p from
the box's lower face (trapezoids, 2000 per line): the cells' faces along a are the surfaces
where it is whole, each a graph over the other two coordinates, computed on a 64×64 grid. The
part is cut into curved slabs between neighbouring faces along x, each along y, each along z
(the outermost slabs reach a millimetre past the box), and each piece's volume taken over its
cell's. Prints JSON: {"status", "cells": [[i, j, k, fraction], ...]}.
"""
import json
import sys

import manifold3d as m3
import numpy as np
import trimesh

GRID = 64
SAMPLES = 2000


def triple(s):
    return [float(v) for v in s.split(",")]


def main():
    path = sys.argv[1]
    origin, size = np.array(triple(sys.argv[2])), np.array(triple(sys.argv[3]))
    counts = [int(v) for v in sys.argv[4].split(",")]
    kind, params = sys.argv[5].split(":")
    assert kind == "radial"
    base, slope, cx, cy = triple(params)

    def field(x, y, z):
        return base + slope * np.sqrt((x - cx) ** 2 + (y - cy) ** 2)

    mesh = trimesh.load(path, force="mesh", process=True)
    solid = m3.Manifold(
        m3.Mesh(
            vert_properties=np.asarray(mesh.vertices, dtype=np.float32),
            tri_verts=np.asarray(mesh.faces, dtype=np.uint32),
        )
    )
    status = str(solid.status())
    lo, hi = origin, origin + size

    def faces(a):
        """For axis a: the other two axes, their grid, and each face's coordinate a on it."""
        b, c = [x for x in range(3) if x != a]
        gb = np.linspace(lo[b] - 1.0, hi[b] + 1.0, GRID)
        gc = np.linspace(lo[c] - 1.0, hi[c] + 1.0, GRID)
        B, C = np.meshgrid(np.clip(gb, lo[b], hi[b]), np.clip(gc, lo[c], hi[c]), indexing="ij")
        t = np.linspace(lo[a], hi[a], SAMPLES + 1)
        p = [None, None, None]
        p[a] = t[None, None, :]
        p[b] = B[:, :, None]
        p[c] = C[:, :, None]
        w = 1.0 / field(*np.broadcast_arrays(*p))
        phi = np.concatenate(
            [np.zeros(w.shape[:2] + (1,)), np.cumsum(0.5 * (w[..., 1:] + w[..., :-1]) * (t[1] - t[0]), axis=-1)],
            axis=-1,
        )
        u = counts[a] * phi / phi[..., -1:]
        out = []
        for i in range(counts[a] + 1):
            if i == 0:
                out.append(np.full(B.shape, lo[a] - 1.0))
            elif i == counts[a]:
                out.append(np.full(B.shape, hi[a] + 1.0))
            else:
                x = np.empty(B.shape)
                for m in range(GRID):
                    for n in range(GRID):
                        x[m, n] = np.interp(i, u[m, n], t)
                out.append(x)
        return b, c, gb, gc, out

    def slab(a, b, c, gb, gc, lower, upper):
        """The closed solid between two faces along a."""
        verts = []
        for surface in (lower, upper):
            p = np.zeros((GRID, GRID, 3))
            p[..., a] = surface
            p[..., b] = gb[:, None]
            p[..., c] = gc[None, :]
            verts.append(p.reshape(-1, 3))
        verts = np.concatenate(verts)
        idx = lambda s, m, n: s * GRID * GRID + m * GRID + n
        tris = []
        for m in range(GRID - 1):
            for n in range(GRID - 1):
                for s, flip in ((0, True), (1, False)):
                    q = [idx(s, m, n), idx(s, m + 1, n), idx(s, m + 1, n + 1), idx(s, m, n + 1)]
                    t1, t2 = [q[0], q[1], q[2]], [q[0], q[2], q[3]]
                    if flip:
                        t1, t2 = t1[::-1], t2[::-1]
                    tris += [t1, t2]
        # The walls round the grid's rim, lower to upper.
        rim = (
            [(m, 0) for m in range(GRID - 1)]
            + [(GRID - 1, n) for n in range(GRID - 1)]
            + [(m, GRID - 1) for m in range(GRID - 1, 0, -1)]
            + [(0, n) for n in range(GRID - 1, 0, -1)]
        )
        for k in range(len(rim)):
            (m0, n0), (m1, n1) = rim[k], rim[(k + 1) % len(rim)]
            a0, a1 = idx(0, m0, n0), idx(0, m1, n1)
            b0, b1 = idx(1, m0, n0), idx(1, m1, n1)
            tris += [[a0, a1, b1], [a0, b1, b0]]
        tris = np.array(tris)
        # Which way round depends on the axes' order: turn the solid outward.
        v = verts[tris]
        signed = np.einsum("ij,ij->i", v[:, 0], np.cross(v[:, 1], v[:, 2])).sum() / 6.0
        if signed < 0:
            tris = tris[:, ::-1]
        s = m3.Manifold(m3.Mesh(vert_properties=verts.astype(np.float32), tri_verts=tris.astype(np.uint32)))
        assert str(s.status()) == "Error.NoError", s.status()
        return s

    slabs = []
    for a in range(3):
        b, c, gb, gc, fs = faces(a)
        slabs.append([slab(a, b, c, gb, gc, fs[i], fs[i + 1]) for i in range(counts[a])])
    box = m3.Manifold.cube(size.tolist()).translate(origin.tolist())
    cells = []
    for i, sx in enumerate(slabs[0]):
        px, bx = solid ^ sx, box ^ sx
        for j, sy in enumerate(slabs[1]):
            pxy, bxy = px ^ sy, bx ^ sy
            for k, sz in enumerate(slabs[2]):
                cells.append([i, j, k, (pxy ^ sz).volume() / (bxy ^ sz).volume()])
    print(json.dumps({"status": status, "cells": cells}))


main()
