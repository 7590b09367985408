"""Reads latvox's CAD output back with independent tools and measures it against the boundary
points: the IGES through OpenCASCADE (gmsh's OCC kernel), the DXF through ezdxf.

Usage: python3 check_cad.py FILE.igs FILE.dxf BOUNDARY.csv OUT.json
Reports, per file, the number of curves and the largest distance from a boundary point to the
nearest curve.
"""
import json
import sys

import ezdxf
import gmsh
import numpy as np

igs, dxf, csv, out = sys.argv[1:5]
pts = np.loadtxt(csv, delimiter=",", skiprows=1)
loops = pts[:, 0].astype(int)

gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("iges")
gmsh.model.occ.importShapes(igs)
gmsh.model.occ.synchronize()
curves = gmsh.model.getEntities(1)
types = sorted({gmsh.model.getType(d, t) for d, t in curves})
iges_worst = 0.0
for p in pts:
    best = np.inf
    for d, t in curves:
        c, _ = gmsh.model.getClosestPoint(d, t, [p[1], p[2], 0.0])
        best = min(best, float(np.hypot(c[0] - p[1], c[1] - p[2])))
    iges_worst = max(iges_worst, best)
gmsh.finalize()

doc = ezdxf.readfile(dxf)
splines = [e for e in doc.modelspace() if e.dxftype() == "SPLINE"]
samples = []
for s in splines:
    bs = s.construction_tool()
    samples.append(np.array([[v.x, v.y] for v in bs.approximate(segments=4000)]))
dxf_worst = 0.0
for p in pts:
    best = min(float(np.min(np.hypot(s[:, 0] - p[1], s[:, 1] - p[2]))) for s in samples)
    dxf_worst = max(dxf_worst, best)

json.dump({
    "loops": int(loops.max() + 1),
    "points": int(len(pts)),
    "iges_curves": len(curves),
    "iges_curve_types": types,
    "iges_max_distance": iges_worst,
    "dxf_splines": len(splines),
    "dxf_control_points": [len(s.control_points) for s in splines],
    "dxf_units": int(doc.header.get("$INSUNITS", 0)),
    "dxf_max_distance": dxf_worst,
}, open(out, "w"))
