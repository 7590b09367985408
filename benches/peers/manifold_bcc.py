"""The BCC strut lattice as a user of a mesh-boolean library builds it: manifold3d (PyPI; the
Manifold library, exact and robust mesh booleans), each strut a cylinder and each node a sphere,
unioned in one batch, intersected with the box, written as binary STL.

Usage: python3 manifold_bcc.py CELLS RADIUS OUT.stl [CELL_SIZE] [SEGMENTS]

The geometry is latvox's `strut --cell bcc --radius RADIUS --cells CELLS`: nodes at the cube
corners and centres of cells of CELL_SIZE mm (5), struts from each centre to its cell's eight
corners, capsules of RADIUS mm (a cylinder and the spheres at its ends), clipped by the box.
SEGMENTS (24) polygon sides per circle.
"""
import sys
import numpy as np
import manifold3d as m3d

cells = int(sys.argv[1])
r = float(sys.argv[2])
out = sys.argv[3]
a = float(sys.argv[4]) if len(sys.argv) > 4 else 5.0
seg = int(sys.argv[5]) if len(sys.argv) > 5 else 24


def cylinder(p, q):
    """A cylinder of radius r from p to q."""
    d = q - p
    h = float(np.linalg.norm(d))
    z = d / h
    # An orthonormal frame with z along the strut.
    t = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(t, z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    m = np.column_stack([x, y, z, p])  # 3×4: columns are the images of x, y, z and the origin
    return m3d.Manifold.cylinder(h, r, r, seg).transform(m)


parts = []
sphere = m3d.Manifold.sphere(r, seg)
corners = np.array([[i & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], dtype=float)
for i in range(cells):
    for j in range(cells):
        for k in range(cells):
            o = np.array([i, j, k], dtype=float) * a
            c = o + 0.5 * a
            parts.append(sphere.translate(c))
            for corner in corners:
                parts.append(cylinder(c, o + corner * a))
for i in range(cells + 1):
    for j in range(cells + 1):
        for k in range(cells + 1):
            parts.append(sphere.translate(np.array([i, j, k], dtype=float) * a))
lattice = m3d.Manifold.batch_boolean(parts, m3d.OpType.Add)
box = m3d.Manifold.cube([cells * a] * 3)
part = lattice ^ box
mesh = part.to_mesh()
v = np.asarray(mesh.vert_properties, dtype=np.float32)[:, :3]
t = np.asarray(mesh.tri_verts, dtype=np.int64)
tri = v[t]  # n × 3 × 3
n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
rec = np.zeros(len(t), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
rec["n"] = n
rec["v"] = tri
with open(out, "wb") as f:
    f.write(b"manifold3d BCC".ljust(80, b" "))
    f.write(np.uint32(len(t)).tobytes())
    f.write(rec.tobytes())
print(f"{len(t)} triangles, volume {part.volume():.3f} mm3, genus {part.genus()}", file=sys.stderr)
