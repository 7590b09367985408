"""Areas of a solid's cross-sections by planes across z, measured by manifold3d (an independent
mesh library).

Usage: slice_areas.py MESH Z0,Z1,...

Prints JSON: a list of the cross-sections' areas, one per height.
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
    heights = [float(z) for z in sys.argv[2].split(",")]
    print(json.dumps([solid.slice(z).area() for z in heights]))


main()
