"""Makes the small input files the book's examples use (run from docs/examples/).

bracket.stl, boss1.stl, boss2.stl: an L-shaped bracket and two blocks kept solid inside it.
broken.stl: a 10 mm cube with one face missing and one facet turned over.
assembly.3mf: two overlapping boxes as two objects (one solid only once united).
scan.xyz: 4,000 points on a sphere of radius 8 mm (x y z per line, no normals), ±0.01 mm noise.
cam.xy: a cam's profile r = 20 + 8·max(0, cos θ)² mm and a 6 mm bore (x y per line).
grade.npy: a 3×3×3 density field, 0.25 at the bottom to 0.4 at the top (x, y, z order).
"""
import io
import math
import struct
import zipfile

import numpy as np


def box(lo, hi):
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    f = [(0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4),
         (1, 2, 6), (1, 6, 5), (2, 3, 7), (2, 7, 6), (3, 0, 4), (3, 4, 7)]
    return v, f


def prism(outline, z0, z1):
    """A closed prism over a counter-clockwise polygon (fan-triangulated caps: convex or L)."""
    n = len(outline)
    v = [(x, y, z0) for x, y in outline] + [(x, y, z1) for x, y in outline]
    f = []
    for i in range(n):
        j = (i + 1) % n
        f += [(i, j, n + j), (i, n + j, n + i)]
    return v, f


def write_stl(path, v, f):
    with open(path, "wb") as out:
        out.write(b"\0" * 80 + struct.pack("<I", len(f)))
        for a, b, c in f:
            pa, pb, pc = (np.array(v[k], float) for k in (a, b, c))
            n = np.cross(pb - pa, pc - pa)
            n = n / np.linalg.norm(n)
            out.write(struct.pack("<12fH", *n, *pa, *pb, *pc, 0))


# The L bracket: a 30 x 20 x 10 mm base and a 10 x 20 x 30 mm upright at x = 0.
# Its cross-section in xz is an L; extrude it along y, caps split into two rectangles.
L = [(0, 0), (30, 0), (30, 10), (10, 10), (10, 30), (0, 30)]  # (x, z), counter-clockwise
verts, faces = [], []
for (x, z) in L:
    verts.append((x, 0.0, z))
for (x, z) in L:
    verts.append((x, 20.0, z))
n = len(L)
for i in range(n):
    j = (i + 1) % n
    # side walls: outward normal when the xz polygon is counter-clockwise seen from -y
    faces += [(i, n + j, j), (i, n + i, n + j)]
# caps: y = 0 faces -y, y = 20 faces +y; the L as two rectangles 0-1-2-3 (+0) and 0-3-4-5
for tri in [(0, 1, 2), (0, 2, 3), (0, 3, 4), (0, 4, 5)]:
    a, b, c = tri
    faces.append((a, b, c))            # y = 0 side (xz counter-clockwise seen from -y: outward)
    faces.append((n + a, n + c, n + b))
write_stl("bracket.stl", verts, faces)
write_stl("boss1.stl", *box((16, 6, 0), (24, 14, 10)))
write_stl("boss2.stl", *box((0, 6, 22), (10, 14, 30)))

v, f = box((0, 0, 0), (10, 10, 10))
f = [t for k, t in enumerate(f) if k not in (2, 3)]    # the top face missing
f[0] = (f[0][0], f[0][2], f[0][1])                      # a facet turned over
write_stl("broken.stl", v, f)


def model_xml(objects):
    parts = ['<?xml version="1.0" encoding="UTF-8"?>\n<model unit="millimeter" '
             'xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02">\n<resources>\n']
    for k, (v, f) in enumerate(objects, 1):
        parts.append(f'<object id="{k}" type="model"><mesh><vertices>\n')
        parts += [f'<vertex x="{x}" y="{y}" z="{z}"/>\n' for x, y, z in v]
        parts.append('</vertices><triangles>\n')
        parts += [f'<triangle v1="{a}" v2="{b}" v3="{c}"/>\n' for a, b, c in f]
        parts.append('</triangles></mesh></object>\n')
    parts.append('</resources>\n<build>\n')
    parts += [f'<item objectid="{k}"/>\n' for k in range(1, len(objects) + 1)]
    parts.append('</build>\n</model>\n')
    return "".join(parts)


def entry(name):
    """A zip entry with a fixed date, so that the package is the same byte for byte."""
    return zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))


with zipfile.ZipFile("assembly.3mf", "w", zipfile.ZIP_DEFLATED) as z:
    z.writestr(entry("[Content_Types].xml"),
               '<?xml version="1.0" encoding="UTF-8"?>\n<Types xmlns="http://schemas.openxmlformats.org/'
               'package/2006/content-types"><Default Extension="rels" ContentType="application/'
               'vnd.openxmlformats-package.relationships+xml"/><Default Extension="model" '
               'ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/></Types>\n')
    z.writestr(entry("_rels/.rels"),
               '<?xml version="1.0" encoding="UTF-8"?>\n<Relationships xmlns="http://schemas.'
               'openxmlformats.org/package/2006/relationships"><Relationship Target="/3D/3dmodel.model" '
               'Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>'
               '</Relationships>\n')
    z.writestr(entry("3D/3dmodel.model"), model_xml([box((0, 0, 0), (20, 10, 10)), box((10, 5, 5), (30, 15, 15))]))

rng = np.random.default_rng(7)
p = rng.normal(size=(4000, 3))
p = p / np.linalg.norm(p, axis=1)[:, None] * (8.0 + rng.uniform(-0.01, 0.01, size=(4000, 1)))
np.savetxt("scan.xyz", p, fmt="%.4f")

t = np.linspace(0, 2 * math.pi, 600, endpoint=False)
r = 20 + 8 * np.maximum(0, np.cos(t)) ** 2
outer = np.c_[r * np.cos(t), r * np.sin(t)]
t = np.linspace(0, 2 * math.pi, 120, endpoint=False)
bore = np.c_[3 * np.cos(t), 3 * np.sin(t)]
np.savetxt("cam.xy", np.r_[outer, bore], fmt="%.4f")

z = np.linspace(0.25, 0.4, 3)
np.save("grade.npy", np.broadcast_to(z, (3, 3, 3)).astype(np.float64).copy())
