"""Writes the parts benches/view.rs draws (bcc10, bcc100, gyroid10, cube10: the same part files,
the cube a 50 mm ASCII STL) into a folder, starts `latvox view` on each and saves the scene the
page gets (`/api/part`'s "scene") as scenes/NAME.json beside this file, for frames.py.

    python3 scenes.py LATVOX_BINARY WORK_DIR
"""

import json
import os
import subprocess
import sys
import urllib.request

PARTS = {
    "bcc10": 'command = "strut"\ncell = "bcc"\ndensity = 0.1\ncells = 10\ncell-size = 5\n',
    "bcc100": 'command = "strut"\ncell = "bcc"\ndensity = 0.1\ncells = 100\ncell-size = 5\n',
    "gyroid10": 'command = "tpms"\ntype = "gyroid"\ndensity = 0.2\ncells = 10\ncell-size = 5\n',
    "cube10": 'command = "fill"\ninput = "cube.stl"\nskin = 1\nlattice = "bcc"\ncell-size = 5\n'
              'density = 0.1\n',
}


def cube_stl(path, lo=0.0, hi=50.0):
    """A cube as ASCII STL: 12 triangles, wound and with normals facing out."""
    c = lambda i: [hi if i & 1 else lo, hi if i & 2 else lo, hi if i & 4 else lo]  # noqa: E731
    quads = [([0, 2, 3, 1], (0, 0, -1)), ([4, 5, 7, 6], (0, 0, 1)), ([0, 1, 5, 4], (0, -1, 0)),
             ([2, 6, 7, 3], (0, 1, 0)), ([0, 4, 6, 2], (-1, 0, 0)), ([1, 3, 7, 5], (1, 0, 0))]
    lines = ["solid cube"]
    for q, n in quads:
        for tri in ([q[0], q[1], q[2]], [q[0], q[2], q[3]]):
            lines.append("  facet normal %g %g %g" % n)
            lines.append("    outer loop")
            lines += ["      vertex %g %g %g" % tuple(c(i)) for i in tri]
            lines += ["    endloop", "  endfacet"]
    lines.append("endsolid cube")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    exe, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "scenes")
    os.makedirs(out, exist_ok=True)
    cube_stl(os.path.join(work, "cube.stl"))
    for name, text in PARTS.items():
        with open(os.path.join(work, name + ".toml"), "w") as f:
            f.write(text)
        server = subprocess.Popen([exe, "view", name + ".toml", "--port", "0", "-q"], cwd=work,
                                  stdout=subprocess.PIPE, text=True)
        try:
            url = server.stdout.readline().strip()
            # The printed URL carries the run's token; the API wants it in a header.
            base, _, token = url.partition("?token=")
            ask = urllib.request.Request(base + "api/part",
                                         headers={"Authorization": "token " + token})
            part = json.load(urllib.request.urlopen(ask, timeout=600))
        finally:
            server.kill()
            server.wait()
        with open(os.path.join(out, name + ".json"), "w") as f:
            json.dump(part["scene"], f, separators=(",", ":"))
        print(name, url, sorted(part), part["scene"]["kind"], part["scene"]["bounds"])


if __name__ == "__main__":
    main()
