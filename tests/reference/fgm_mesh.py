"""Reads an FGM part's meshes with independent libraries and reports, as JSON, what the tests
check: from the 3MF (lib3mf) the base materials, the composite group's size and, per triangle
corner, the vertex and its mixing ratios; from the PLY (trimesh) the vertices and their colours.

usage: python3 fgm_mesh.py PART.3mf PART.ply > out.json
"""
import json
import sys

import lib3mf
import trimesh

threemf, ply = sys.argv[1], sys.argv[2]
wrapper = lib3mf.get_wrapper()
model = wrapper.CreateModel()
model.QueryReader("3mf").ReadFromFile(threemf)
bases, composites, corners, triangles = [], None, [], 0
resources = model.GetResources()
while resources.MoveNext():
    r = resources.GetCurrent()
    if isinstance(r, lib3mf.BaseMaterialGroup):
        bases = [r.GetName(i) for i in r.GetAllPropertyIDs()]
    elif isinstance(r, lib3mf.CompositeMaterials):
        composites = r
    elif isinstance(r, lib3mf.MeshObject):
        triangles = r.GetTriangleCount()
        vertices = r.GetVertices()
        for t in range(0, triangles, max(1, triangles // 500)):
            tri = r.GetTriangle(t)
            props = r.GetTriangleProperties(t)
            for k in range(3):
                v = vertices[tri.Indices[k]]
                mix = composites.GetComposite(props.PropertyIDs[k])
                corners.append([list(v.Coordinates), [m.MixingRatio for m in mix]])
mesh = trimesh.load(ply, process=False)
colours = mesh.visual.vertex_colors[:, :3].tolist()
json.dump(
    {
        "bases": bases,
        "composites": composites.GetCount() if composites else 0,
        "triangles": triangles,
        "corners": corners,
        "ply_vertices": mesh.vertices.tolist()[:2000],
        "ply_colours": colours[:2000],
    },
    sys.stdout,
)
