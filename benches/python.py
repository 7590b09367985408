"""latvox from Python beside its closest Python peer, and beside its own command line.

    python3 benches/python.py [--runs 5]

Needs the package (`pip install .`) and, for the peer, PyScaffolder 1.5.4
(`pip install PyScaffolder==1.5.4`, C++ through pybind11; skipped when absent). Each run is its
own process, so that its peak memory is its own; the two sides alternate, A B A B …, and the
medians and the median of the pair-by-pair ratios are printed.

1. A 20 mm cube filled with gyroid at 128 samples across, as PyScaffolder's `generate_scaffold`
   makes it (its coefficient π: cells of 2 mm, 12.8 samples a cell, the solid at level 0): latvox
   makes the same cells at 13 voxels a cell at the solid fraction PyScaffolder's part has, and
   verifies it. Time and peak memory of each, triangles, the density each reaches.
2. The same latvox part from Python (`latvox.tpms(..., output=...)`) and from the command line
   (`latvox tpms ... -o`): the Python call's overhead; and the part kept in memory as NumPy
   arrays (no output) beside the command line writing it.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

PEER = r"""
import json, resource, time
import numpy as np
import PyScaffolder
v = np.array([[x, y, z] for x in (0, 20) for y in (0, 20) for z in (0, 20)], dtype=np.float64)
f = np.array([[0,1,3],[0,3,2],[4,6,7],[4,7,5],[0,4,5],[0,5,1],[2,3,7],[2,7,6],[0,2,6],[0,6,4],
              [1,5,7],[1,7,3]], dtype=np.int32)
p = PyScaffolder.Parameter()
p.surface_name = "gyroid"
p.grid_size = 128
p.isolevel = 0.0
t = time.perf_counter()
m = PyScaffolder.generate_scaffold(v, f, p)
dt = time.perf_counter() - t
print(json.dumps({"seconds": dt, "triangles": len(m.f), "density": 1 - m.porosity,
                  "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""

LATVOX = r"""
import json, resource, sys, time
import latvox
t = time.perf_counter()
m = latvox.tpms(type="gyroid", density=float(sys.argv[1]), cells=10, cell_size=2.0,
                resolution=13)
dt = time.perf_counter() - t
print(json.dumps({"seconds": dt, "triangles": len(m.faces),
                  "density": m.report["achieved_density"], "closed": m.report["checks"]["closed"],
                  "self_intersecting": m.report["checks"]["self_intersecting"],
                  "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""

PART = ["--type", "gyroid", "--density", "0.3", "--cells", "6", "--cell-size", "5"]

OVERHEAD = r"""
import json, sys, time, latvox
t = time.perf_counter()
m = latvox.tpms(type="gyroid", density=0.3, cells=6, cell_size=5.0,
                output=sys.argv[1] if sys.argv[1] != "-" else None)
print(json.dumps({"seconds": time.perf_counter() - t}))
"""


def run(args):
    out = subprocess.run(args, capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def timed(args):
    t = time.perf_counter()
    subprocess.run(args, capture_output=True, check=True)
    return time.perf_counter() - t


def median(xs):
    return statistics.median(xs)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=5)
    a = ap.parse_args()
    exe = os.environ.get("LATVOX_BIN", os.path.join(ROOT, "target", "release", "latvox"))
    try:
        import PyScaffolder  # noqa: F401
        have_peer = True
    except ImportError:
        have_peer = False
        print("PyScaffolder is not installed: the peer is skipped")
    print(f"{os.cpu_count()} cores; {a.runs} runs each, alternating\n")

    if have_peer:
        first = run([sys.executable, "-c", PEER])
        density = round(first["density"], 3)
        peer, ours = [], []
        for _ in range(a.runs):
            peer.append(run([sys.executable, "-c", PEER]))
            ours.append(run([sys.executable, "-c", LATVOX, str(density)]))
        ratio = median([p["seconds"] / o["seconds"] for p, o in zip(peer, ours)])
        print("1. A 20 mm gyroid cube, 128 samples across (cells of 2 mm, 12.8 samples a cell)")
        print("| | seconds (median) | peak MB (median) | triangles | density | verified |")
        print("| --- | --- | --- | --- | --- | --- |")
        print(f"| PyScaffolder 1.5.4 | {median([p['seconds'] for p in peer]):.2f} | "
              f"{median([p['peak_mb'] for p in peer]):.0f} | {peer[0]['triangles']:,} | "
              f"{peer[0]['density']:.4f} (level 0) | no |")
        o = ours[0]
        print(f"| latvox (13 voxels a cell) | {median([x['seconds'] for x in ours]):.2f} | "
              f"{median([x['peak_mb'] for x in ours]):.0f} | {o['triangles']:,} | "
              f"{o['density']:.4f} (target {density}) | closed {o['closed']}, "
              f"self-intersecting {o['self_intersecting']} |")
        print(f"PyScaffolder / latvox time, median of the pairs: {ratio:.1f}×\n")

    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "g.stl")
        py, mem, cli, call, call_mem = [], [], [], [], []
        timed([exe, "tpms", *PART, "-o", out, "-q"])
        for _ in range(a.runs):
            t = time.perf_counter()
            call.append(run([sys.executable, "-c", OVERHEAD, out])["seconds"])
            py.append(time.perf_counter() - t)
            cli.append(timed([exe, "tpms", *PART, "-o", out, "-q"]))
            t = time.perf_counter()
            call_mem.append(run([sys.executable, "-c", OVERHEAD, "-"])["seconds"])
            mem.append(time.perf_counter() - t)
        start = median([timed([sys.executable, "-c", "import latvox"]) for _ in range(a.runs)])
    print("2. `tpms " + " ".join(PART) + "`, whole processes (medians)")
    print(f"- command line, written to STL: {median(cli):.3f} s")
    print(f"- Python, written to STL (output=): process {median(py):.3f} s, the call "
          f"{median(call):.3f} s; the call / the command line, median of the pairs: "
          f"{median([p / c for p, c in zip(call, cli)]):.3f} (the process: "
          f"{median([p / c for p, c in zip(py, cli)]):.3f})")
    print(f"- Python, kept in memory as NumPy arrays: process {median(mem):.3f} s, the call "
          f"{median(call_mem):.3f} s; the call / the command line: "
          f"{median([m / c for m, c in zip(call_mem, cli)]):.3f}")
    print(f"- of each Python process, starting Python and importing latvox: {start:.3f} s")


if __name__ == "__main__":
    main()
