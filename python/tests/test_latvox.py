"""latvox's Python package, checked against the command line and against trimesh."""

import json
import os
import signal
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest
import trimesh

import latvox

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "docs" / "examples"


def cli():
    """The latvox binary built beside this package (cargo build --release)."""
    exe = os.environ.get("LATVOX_BIN") or str(ROOT / "target" / "release" / "latvox")
    if not os.path.exists(exe):
        pytest.skip("no latvox binary (cargo build --release)")
    return exe


def closed_solid(m: latvox.Mesh) -> trimesh.Trimesh:
    t = trimesh.Trimesh(m.vertices, m.faces, process=False)
    assert t.is_watertight
    assert t.is_winding_consistent
    assert t.volume > 0
    return t


def run_cli(tmp_path, *args):
    out = subprocess.run([cli(), *map(str, args), "-q"], cwd=tmp_path, capture_output=True,
                         text=True)
    return out


def test_tpms_is_the_command_lines_part(tmp_path):
    m = latvox.tpms(type="gyroid", density=0.3, cells=3, cell_size=5.0, resolution=20)
    t = closed_solid(m)
    # The report is the command line's, measured on this very mesh.
    assert m.report["target_density"] == 0.3
    assert abs(m.report["achieved_density"] - 0.3) <= 0.002
    assert len(m.faces) == m.report["triangles"]
    assert t.volume == pytest.approx(m.report["volume"], rel=1e-6)
    assert m.volume == pytest.approx(t.volume, rel=1e-9)
    assert t.volume / 15.0**3 == pytest.approx(m.report["achieved_density"], rel=1e-6)
    # The same options on the command line make the same part.
    r = run_cli(tmp_path, "tpms", "--type", "gyroid", "--density", "0.3", "--cells", "3",
                "--cell-size", "5", "--resolution", "20", "-o", "g.stl", "--report", "g.json")
    assert r.returncode == 0, r.stderr
    report = json.loads((tmp_path / "g.json").read_text())
    assert report["achieved_density"] == m.report["achieved_density"]
    assert report["triangles"] == m.report["triangles"]
    stl = trimesh.load(tmp_path / "g.stl")
    assert stl.volume == pytest.approx(t.volume, rel=1e-6)


def test_strut_takes_tuples_and_reports_its_density():
    m = latvox.strut(cell="octet", density=0.15, cells=(2, 2, 1), cell_size=5.0)
    t = closed_solid(m)
    assert m.report["cells"] == [2, 2, 1]
    assert t.volume / (10 * 10 * 5) == pytest.approx(0.15, abs=0.002)
    assert t.bounds[1] == pytest.approx([10, 10, 5], abs=1e-3)


def test_voronoi_foam_at_its_density_and_the_same_seed_again():
    a = latvox.voronoi(spacing=3.0, density=0.15, size=(10.0, 8.0, 6.0), resolution=10, seed=4)
    t = closed_solid(a)
    assert t.volume / (10 * 8 * 6) == pytest.approx(0.15, abs=0.002)
    assert a.report["foam"]["cells"] > 10
    b = latvox.voronoi(spacing=3.0, density=0.15, size=(10.0, 8.0, 6.0), resolution=10, seed=4)
    assert np.array_equal(a.vertices, b.vertices)


def test_periodic_voronoi_foam_repeats_its_cell():
    m = latvox.voronoi(spacing=3.0, periodic=6.0, density=0.2, size=(12.0, 12.0, 6.0),
                       resolution=8, seed=2)
    t = closed_solid(m)
    assert m.report["period"] == 6.0
    assert t.volume / (12 * 12 * 6) == pytest.approx(0.2, abs=0.002)
    # The cell repeats: the section at x = 1 is the section at x = 7 moved by a cell (the
    # field is sampled alike in every cell; the y and z of every crossing are the same).
    a = t.section(plane_origin=[1.0, 0, 0], plane_normal=[1, 0, 0])
    b = t.section(plane_origin=[7.0, 0, 0], plane_normal=[1, 0, 0])
    assert a.length > 10.0
    assert a.length == pytest.approx(b.length, rel=1e-6)
    assert np.allclose(np.sort(a.vertices[:, 1:], axis=0), np.sort(b.vertices[:, 1:], axis=0),
                       atol=1e-5)


def test_fill_a_part_with_a_lattice():
    m = latvox.fill(str(EXAMPLES / "sphere.obj"), lattice="gyroid", density=0.2, skin=1.0,
                    cell_size=6.0, resolution=12)
    closed_solid(m)
    assert abs(m.report["achieved_density"] - 0.2) <= 0.002


def test_fgm_from_a_scan():
    m = latvox.fgm(points=str(EXAMPLES / "scan.xyz"))
    closed_solid(m)


def test_topopt_to_cad():
    d = latvox.topopt(problem="mbb", nelx=30, nely=10, volfrac=0.5)
    assert d.array.shape == (10, 30)
    assert d.array.mean() == pytest.approx(0.5, abs=0.01)
    assert d.report["nelx"] == 30
    m = latvox.interpret(d, thickness=4.0)
    t = closed_solid(m)
    assert m.report["checks"]["closed"]
    # The part is the field's solid region, extruded: its volume is near the field's.
    assert t.volume == pytest.approx(d.array.mean() * 30 * 10 * 4.0, rel=0.25)


def test_homogenize_gives_the_tensor_and_constants():
    r = latvox.homogenize(type="gyroid", structure="sheet", density=0.2, voxels=16)
    c = np.array(r["stiffness"])
    assert c.shape == (6, 6)
    assert np.allclose(c, c.T)
    assert r["relative_density"] == pytest.approx(0.2, abs=1e-4)
    # Young's modulus along x from the compliance, as the report gives it.
    assert r["constants"]["young"][0] == pytest.approx(1.0 / np.linalg.inv(c)[0, 0], rel=1e-9)
    with pytest.raises(latvox.InputError):
        latvox.homogenize(cell="bcc", level=0.3)


def box(size=1.0):
    b = trimesh.creation.box(extents=[size] * 3)
    return np.asarray(b.vertices), np.asarray(b.faces)


def test_check_takes_every_kind_of_mesh(tmp_path):
    v, f = box(2.0)
    reports = [
        latvox.check((v, f)),
        latvox.check(latvox.Mesh(v, f)),
        latvox.check(trimesh.Trimesh(v, f)),
    ]
    latvox.Mesh(v, f).save(tmp_path / "box.stl")
    reports.append(latvox.check(tmp_path / "box.stl"))
    for r in reports:
        assert r["valid_solid"] is True
        assert r["triangles"] == 12
    # The same fields as `latvox check --json`.
    out = run_cli(tmp_path, "check", "box.stl", "--json")
    assert out.returncode == 0, out.stderr
    assert set(json.loads(out.stdout)) == set(reports[-1])
    # An open box: defects, a DefectError only when asked.
    r = latvox.check((v, f[:-1]))
    assert r["valid_solid"] is False
    with pytest.raises(latvox.DefectError) as e:
        latvox.check((v, f[:-1]), strict=True)
    assert e.value.report["valid_solid"] is False


def test_repair_makes_a_solid():
    m = latvox.repair(str(EXAMPLES / "broken.stl"), solid=True)
    t = closed_solid(m)
    assert m.report["valid_solid"] is True
    # An open box (a face missing) is closed again, its volume the box's.
    v, f = box(2.0)
    fixed = latvox.repair((v, f[:-2]))
    assert closed_solid(fixed).volume == pytest.approx(8.0, rel=1e-6)


def shoelace(p):
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def test_slice_gives_the_sections():
    v, f = box(2.0)
    layers = latvox.slice((v + 1.0, f), layer=0.25)
    assert len(layers) == 8
    for k, layer in enumerate(layers):
        assert layer.z == pytest.approx(0.25 * (k + 1), abs=1e-6)
        assert len(layer.polygons) == 1
        assert shoelace(layer.polygons[0]) == pytest.approx(4.0, rel=1e-6)
    # A part file is sliced from its implicit solid, not meshed.
    gyroid = latvox.slice(str(EXAMPLES / "gyroid.toml"), layer=1.0)
    assert len(gyroid) == 15
    assert all(len(l.polygons) > 0 for l in gyroid)


def test_render_is_an_image(tmp_path):
    img = latvox.render(str(EXAMPLES / "gyroid.toml"), 64, 48)
    assert img.shape == (48, 64, 3) and img.dtype == np.uint8
    # The part covers some pixels and the background others.
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 10
    # The same picture as the command line's PNG, read by an independent decoder.
    r = run_cli(tmp_path, "render", EXAMPLES / "gyroid.toml", "-o", "g.png", "--width", "64",
                "--height", "48")
    assert r.returncode == 0, r.stderr
    import zlib

    data = (tmp_path / "g.png").read_bytes()
    chunks, pos = [], 8
    while pos < len(data):
        n = int.from_bytes(data[pos:pos + 4], "big")
        kind = data[pos + 4:pos + 8]
        if kind == b"IHDR":
            w, h, depth, colour = (int.from_bytes(data[pos + 8:pos + 12], "big"),
                                   int.from_bytes(data[pos + 12:pos + 16], "big"),
                                   data[pos + 16], data[pos + 17])
        if kind == b"IDAT":
            chunks.append(data[pos + 8:pos + 8 + n])
        pos += 12 + n
    assert (w, h, depth) == (64, 48, 8)
    channels = {2: 3, 6: 4}[colour]
    raw = zlib.decompress(b"".join(chunks))
    stride = w * channels
    prev = bytearray(stride)
    picture = []
    for k in range(h):
        kind, line = raw[k * (stride + 1)], bytearray(raw[k * (stride + 1) + 1:(k + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b, c = prev[i], prev[i - channels] if i >= channels else 0
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        picture.append(np.frombuffer(bytes(line), dtype=np.uint8).reshape(w, channels)[:, :3])
        prev = line
    assert np.array_equal(np.stack(picture), img)
    assert latvox.render(latvox.load_part(EXAMPLES / "gyroid.toml"), 64, 48).shape == img.shape


def test_part_files_load_and_make(tmp_path):
    p = latvox.load_part(EXAMPLES / "gyroid.toml")
    assert p.command == "tpms"
    assert p.settings["type"] == "gyroid"
    m = p.make(resolution=16)
    same = latvox.tpms(type="gyroid", structure="net", density=0.3, cells=3, cell_size=5,
                       resolution=16)
    assert np.array_equal(m.faces, same.faces)
    assert np.array_equal(m.vertices, same.vertices)


def test_meshes_round_trip_and_become_trimesh(tmp_path):
    m = latvox.tpms(type="diamond" if False else "d", density=0.4, cells=1, cell_size=4,
                    resolution=16)
    for ext in ["stl", "ply", "obj", "off", "3mf"]:
        path = tmp_path / f"d.{ext}"
        m.save(path)
        back = latvox.Mesh.load(path)
        assert back.volume == pytest.approx(m.volume, rel=1e-5)
    t = m.to_trimesh()
    assert t.is_watertight and t.volume == pytest.approx(m.volume)


def test_arrays_are_handed_over_not_copied():
    m = latvox.tpms(type="gyroid", density=0.3, cells=1, cell_size=5, resolution=16)
    # faces is the buffer latvox built: owned by a Rust container, not a NumPy copy.
    assert not m.faces.flags.owndata
    assert type(m.faces.base).__name__ == "PySliceContainer"
    assert m.faces.dtype == np.uint32 and m.faces.flags.c_contiguous
    assert m.vertices.dtype == np.float64 and m.vertices.flags.writeable
    # Arrays given in the right type and layout are used as they are.
    v, f = box()
    f = f.astype(np.uint32)
    mine = latvox.Mesh(v, f)
    assert np.shares_memory(mine.vertices, v) and np.shares_memory(mine.faces, f)


def test_errors_are_exceptions_by_kind(tmp_path):
    with pytest.raises(latvox.InputError) as e:
        latvox.tpms(density=1.5, cells=1, cell_size=5)
    assert isinstance(e.value, ValueError) and e.value.setting == "density"
    assert "density must be strictly between 0 and 1" in str(e.value)
    with pytest.raises(latvox.InputError) as e:
        latvox.tpms(type="p", density=0.01, cells=2, cell_size=5)
    assert e.value.setting == "density" and e.value.value == 0.01
    assert 0.01 < e.value.min < e.value.max <= 1
    with pytest.raises(latvox.InputError) as e:
        latvox.tpms(type="p", structure="sheet", density=0.08, cells=2, cell_size=5,
                    resolution=8, fixed_resolution=True)
    assert e.value.requested == 8 and e.value.needed > 8
    with pytest.raises(latvox.InputError) as e:
        latvox.tpms(cell_sise=5)
    assert "did you mean cell_size" in str(e.value)
    with pytest.raises(latvox.InputError) as e:
        latvox.check(tmp_path / "missing.stl")
    assert e.value.path.endswith("missing.stl")
    (tmp_path / "junk.stl").write_bytes(b"solid x\n facet normal 0 0\n")
    with pytest.raises(latvox.InputError):
        latvox.check(tmp_path / "junk.stl")
    with pytest.raises(latvox.InputError):
        latvox.Mesh(np.zeros((4, 2)), np.zeros((1, 3)))
    with pytest.raises(latvox.InputError):
        latvox.check((np.zeros((3, 3)), np.array([[0, 1, 7]])))
    # A vertex at infinity has no level set (OpenVDB would refuse it: latvox says so first).
    v, f = box()
    v[0] = np.inf
    with pytest.raises(latvox.InputError) as e:
        latvox.Mesh(v, f).save(tmp_path / "inf.vdb")
    assert "not finite" in str(e.value)
    assert not (tmp_path / "inf.vdb").exists()


def test_an_output_named_is_written_and_returned(tmp_path):
    out = tmp_path / "g.3mf"
    m = latvox.tpms(type="gyroid", density=0.3, cells=1, cell_size=5, resolution=16,
                    output=out)
    assert out.exists()
    assert m.report["output"] == str(out)
    assert latvox.Mesh.load(out).volume == pytest.approx(m.volume, rel=1e-6)


def test_ctrl_c_stops_a_long_part_within_a_second_and_writes_nothing(tmp_path):
    out = tmp_path / "big.stl"
    fired = []

    def interrupt():
        fired.append(time.monotonic())
        os.kill(os.getpid(), signal.SIGINT)

    for output in [None, out]:
        timer = threading.Timer(0.5, interrupt)
        timer.start()
        with pytest.raises(KeyboardInterrupt):
            latvox.tpms(type="gyroid", density=0.3, cells=12, cell_size=5, resolution=48,
                        output=output)
        assert time.monotonic() - fired[-1] < 1.0
    # The work stops at its next batch of triangles; nothing appears, even later.
    time.sleep(3)
    assert list(tmp_path.iterdir()) == []


def test_the_gil_is_released_while_latvox_works():
    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(time.monotonic())
            time.sleep(0.01)

    t = threading.Thread(target=tick)
    t.start()
    start = time.monotonic()
    latvox.tpms(type="gyroid", density=0.3, cells=4, cell_size=5, resolution=32)
    elapsed = time.monotonic() - start
    done.set()
    t.join()
    # The other thread ran all along (ticks every ~10 ms, not only before and after).
    during = [x for x in ticks if start < x < start + elapsed]
    assert elapsed > 0.2
    assert len(during) >= 0.3 * elapsed / 0.01


def test_progress_goes_to_a_callback_and_threads_bound_the_work(capfd):
    stages = []
    m = latvox.tpms(type="gyroid", density=0.3, cells=2, cell_size=5, resolution=16,
                    progress=stages.append, threads=1)
    assert len(m.faces) > 0
    assert any("level" in s or "calibrat" in s for s in stages), stages
    out, err = capfd.readouterr()
    # Nothing on stdout or stderr: summaries and warnings are the report's.
    assert out == "" and err == ""
    with pytest.raises(latvox.InputError):
        latvox.tpms(cells=1, cell_size=5, threads=0)
    # progress=True: a tqdm bar (on stderr), closed when the part is made.
    pytest.importorskip("tqdm")
    latvox.tpms(type="gyroid", density=0.3, cells=1, cell_size=5, resolution=16, progress=True)


def test_help_is_the_command_lines():
    for name in ["tpms", "strut", "fill", "fgm", "topopt", "interpret", "check", "repair",
                 "slice", "render"]:
        doc = getattr(latvox, name).__doc__
        assert doc.startswith(f"latvox.{name}("), doc[:80]
        assert "Options:" in doc and f"latvox {name}" in doc
    assert "--cell-size" in latvox.tpms.__doc__


def test_the_stub_is_current():
    """latvox/__init__.pyi is what python/stubgen.py writes from the commands' definitions."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("stubgen", ROOT / "python" / "stubgen.py")
    stubgen = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(stubgen)
    committed = (ROOT / "python" / "latvox" / "__init__.pyi").read_text()
    assert stubgen.stub() == committed, "run python3 python/stubgen.py"


@pytest.mark.long
def test_millions_of_triangles_come_back_without_doubling_the_peak(tmp_path):
    script = (
        "import latvox, resource\n"
        "m = latvox.tpms(type='gyroid', density=0.3, cells=8, cell_size=5, resolution=36)\n"
        "print(len(m.faces), resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)\n"
    )
    import sys

    py = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                        cwd=tmp_path)
    assert py.returncode == 0, py.stderr
    triangles, peak_kb = map(int, py.stdout.split())
    assert triangles >= 3_500_000
    r = subprocess.run(["/usr/bin/time", "-f", "%M", cli(), "tpms", "--type", "gyroid",
                        "--density", "0.3", "--cells", "8", "--cell-size", "5",
                        "--resolution", "36", "-o", "g.ply", "-q"],
                       capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    cli_kb = int(r.stderr.strip().splitlines()[-1])
    # The command line writing the same part as PLY (an indexed mesh, as the arrays are).
    assert peak_kb < 2 * cli_kb, (peak_kb, cli_kb)
