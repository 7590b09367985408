"""Reads Common Layer Interface files independently of latvox and checks every layer with shapely.

Usage: cli_layers.py ASCII.cli [BINARY.cli]

The ASCII file is parsed from its text, the binary one from the layout of the CLI 2.0
specification (header up to $$HEADEREND, then little-endian commands: uint16 127 = long layer
with a real32 z; uint16 130 = long polyline: int32 id, dir, n, then n real32 pairs). Prints one
JSON object: per layer its z, ring count, hole count, shapely area, and the defects found:
rings not closed or not simple, a ring's orientation disagreeing with its nesting depth (outer
counter-clockwise at even depth, holes clockwise at odd depth), rings that touch or cross, an
invalid multipolygon; and the largest difference between the ASCII and binary polygons.
"""
import json
import struct
import sys

from shapely.geometry import LinearRing, Point, Polygon
from shapely.strtree import STRtree
from shapely.validation import explain_validity


def read_ascii(path):
    text = open(path, encoding="ascii").read()
    head, geom = text.split("$$HEADEREND", 1)
    assert head.startswith("$$HEADERSTART"), "no $$HEADERSTART"
    assert "$$ASCII" in head and "$$VERSION/200" in head, head
    layers = []
    for line in geom.split("\n"):
        line = line.strip()
        if line.startswith("$$LAYER/"):
            layers.append((float(line[8:]), []))
        elif line.startswith("$$POLYLINE/"):
            v = line[11:].split(",")
            pid, d, n = int(v[0]), int(v[1]), int(v[2])
            xy = [float(t) for t in v[3:]]
            assert len(xy) == 2 * n, (len(xy), n)
            layers[-1][1].append((d, [(xy[2 * i], xy[2 * i + 1]) for i in range(n)]))
    declared = int(head.split("$$LAYERS/")[1].split()[0])
    assert declared == len(layers), (declared, len(layers))
    return layers


def read_binary(path):
    data = open(path, "rb").read()
    end = data.index(b"$$HEADEREND") + len(b"$$HEADEREND")
    head = data[:end].decode("ascii")
    assert "$$BINARY" in head, head
    i, layers = end, []
    while i < len(data):
        (ci,) = struct.unpack_from("<H", data, i)
        i += 2
        if ci == 127:
            (z,) = struct.unpack_from("<f", data, i)
            i += 4
            layers.append((z, []))
        elif ci == 130:
            pid, d, n = struct.unpack_from("<iii", data, i)
            i += 12
            xy = struct.unpack_from("<%df" % (2 * n), data, i)
            i += 8 * n
            layers[-1][1].append((d, [(xy[2 * k], xy[2 * k + 1]) for k in range(n)]))
        else:
            raise ValueError("unknown command %d at byte %d" % (ci, i - 2))
    return layers


def check_layer(polylines):
    defects = []
    rings = []
    for d, pts in polylines:
        if d == 2 or pts[0] != pts[-1]:
            defects.append("open polyline")
            continue
        r = LinearRing(pts)
        if not r.is_simple:
            defects.append("ring not simple")
        if (d == 1) != r.is_ccw:
            defects.append("direction code disagrees with the ring's orientation")
        rings.append((r, Polygon(pts)))
    tree = STRtree([r for r, _ in rings])
    for a, (ra, _) in enumerate(rings):
        for b in tree.query(ra):
            if b > a and ra.intersects(rings[b][0]):
                defects.append("rings %d and %d touch or cross" % (a, b))
    # Nesting depth from containment alone, then orientation must follow it.
    depth = []
    for a, (ra, _) in enumerate(rings):
        p = Point(ra.coords[0])
        depth.append(sum(1 for b in tree.query(p) if b != a and rings[b][1].contains(p)))
    for a, (ra, _) in enumerate(rings):
        if ra.is_ccw != (depth[a] % 2 == 0):
            defects.append("ring %d at depth %d has the wrong orientation" % (a, depth[a]))
    # Polygons: each even-depth ring with the rings one level deeper inside it.
    area = 0.0
    for a, (ra, pa) in enumerate(rings):
        if depth[a] % 2:
            continue
        holes = [
            list(rings[b][0].coords)
            for b in tree.query(pa)
            if depth[b] == depth[a] + 1 and pa.contains(Point(rings[b][0].coords[0]))
        ]
        poly = Polygon(list(ra.coords), holes)
        if not poly.is_valid:
            defects.append("invalid polygon: " + explain_validity(poly))
        area += poly.area
    holes = sum(1 for d in depth if d % 2)
    return {"rings": len(rings), "holes": holes, "area": area, "defects": defects[:5]}


def main():
    a = read_ascii(sys.argv[1])
    out = {"layers": [dict(z=z, **check_layer(p)) for z, p in a]}
    if len(sys.argv) > 2:
        b = read_binary(sys.argv[2])
        assert len(a) == len(b), (len(a), len(b))
        worst = 0.0
        for (za, pa), (zb, pb) in zip(a, b):
            worst = max(worst, abs(za - zb))
            assert len(pa) == len(pb), (za, len(pa), len(pb))
            for (da, xa), (db, xb) in zip(pa, pb):
                assert da == db and len(xa) == len(xb)
                for p, q in zip(xa, xb):
                    worst = max(worst, abs(p[0] - q[0]), abs(p[1] - q[1]))
        out["binary_max_difference"] = worst
    print(json.dumps(out))


main()
