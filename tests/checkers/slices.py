"""Cross-sections of a solid by planes across z, measured by manifold3d (an independent mesh
library): each one's area, and the area of what it and the first one do not share (their
symmetric difference: 0 where the two are the same figure).

Usage: slices.py MESH Z0,Z1,...

Prints JSON: [[area, area not shared with Z0's], ...], one per height.
"""
import json
import sys

import manifold3d as m3
import numpy as np
import trimesh


def main():
    mesh = trimesh.load(sys.argv[1], force="mesh", process=True)
    solid = m3.Manifold(
        m3.Mesh(
            vert_properties=np.asarray(mesh.vertices, dtype=np.float32),
            tri_verts=np.asarray(mesh.faces, dtype=np.uint32),
        )
    )
    sections = [solid.slice(float(z)) for z in sys.argv[2].split(",")]
    first = sections[0]
    print(json.dumps([
        [s.area(), (s - first).area() + (first - s).area()] for s in sections
    ]))


main()
