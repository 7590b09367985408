"""latvox from Python: TPMS and strut lattices, lattice-filled parts, graded materials and density
fields to CAD, made at an exact density and verified closed, as NumPy arrays.

Every command of the ``latvox`` command line is a function here, its options keyword arguments
(dashes become underscores, the same names and defaults)::

    import latvox
    part = latvox.tpms(type="gyroid", density=0.3, cells=4, cell_size=5.0)
    part.vertices, part.faces        # (N, 3) float64, (M, 3) uint32
    part.report["density"]           # the same report as ``latvox tpms --report``
    part.save("gyroid.3mf")

``help(latvox.tpms)`` shows the command's options and examples. latvox works with the GIL
released; Ctrl-C stops it (``KeyboardInterrupt``, nothing written); ``progress=True`` draws a tqdm
bar (or pass a function, called with each stage's name); ``threads=N`` bounds its workers.
Errors are :class:`Error`'s kinds: :class:`InputError` (a ``ValueError``), :class:`DefectError`
(only with ``strict=True``) and :class:`BackendError` (a ``RuntimeError``).
"""

from __future__ import annotations

import difflib
import json
import os
import tempfile
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _latvox

__all__ = [
    "Mesh",
    "Part",
    "Layer",
    "Density",
    "Error",
    "InputError",
    "DefectError",
    "BackendError",
    "tpms",
    "strut",
    "voronoi",
    "fill",
    "fgm",
    "topopt",
    "homogenize",
    "interpret",
    "check",
    "repair",
    "slice",
    "render",
    "load_part",
]


class Error(Exception):
    """Every latvox error. ``str(e)`` is the command line's one-line message."""


class InputError(Error, ValueError):
    """Bad input: an unknown or out-of-range option, a density the part cannot meet, a file that
    cannot be read. Where latvox knows them, the attributes say what: ``setting`` (the option),
    ``value``, ``min`` and ``max`` (the range that can be met), ``requested`` and ``needed`` (voxels
    per cell asked for and the least that works), ``path`` (the file)."""

    def __init__(self, message: str, data: Optional[Dict[str, Any]] = None):
        super().__init__(message)
        data = data or {}
        self.setting: Optional[str] = data.get("setting")
        self.value: Optional[float] = data.get("value")
        self.min: Optional[float] = data.get("min")
        self.max: Optional[float] = data.get("max")
        self.requested: Optional[int] = data.get("requested")
        self.needed: Optional[int] = data.get("needed")
        self.path: Optional[str] = data.get("path")


class DefectError(Error):
    """A check found defects (where the command line exits with 1), raised only when the call
    asked ``strict=True``. ``result`` is what was made anyway, ``report`` its report."""

    def __init__(self, message: str, result: Any, report: Dict[str, Any]):
        super().__init__(message)
        self.result = result
        self.report = report


class BackendError(Error, RuntimeError):
    """OpenVDB or CGAL failed unexpectedly (exit code 3 on the command line): a bug to report."""


def _raised(f: Exception) -> Error:
    kind, message, data = f.args
    data = json.loads(data)
    if kind == "backend":
        return BackendError(message)
    return InputError(message, data)


class Mesh:
    """A triangle mesh: ``vertices`` (N, 3) float64 in mm, ``faces`` (M, 3) uint32, wound
    outward, and the ``report`` of the command that made it (a dict, empty for a mesh made from
    arrays).

    A mesh latvox makes hands over its own buffers: ``faces`` is the very array latvox built (no
    copy; its ``base`` holds it), ``vertices`` the float32 positions widened once. Both are
    writeable and belong to this mesh. ``Mesh(vertices, faces)`` makes one from any array-likes
    (copied only where the type or layout differs).
    """

    def __init__(self, vertices: Any, faces: Any, report: Optional[Dict[str, Any]] = None):
        v = np.ascontiguousarray(vertices, dtype=np.float64)
        f = np.ascontiguousarray(faces, dtype=np.uint32)
        if v.ndim != 2 or v.shape[1] != 3 or f.ndim != 2 or f.shape[1] != 3:
            raise InputError(
                f"a mesh is vertices (N, 3) and faces (M, 3), got {v.shape} and {f.shape}"
            )
        self._arrays: Optional[Tuple[np.ndarray, np.ndarray]] = (v, f)
        self._file: Optional[str] = None
        self.report: Dict[str, Any] = report if report is not None else {}

    @classmethod
    def _written(cls, path: str, report: Dict[str, Any]) -> "Mesh":
        """The mesh a command wrote to `path`, read when its arrays are first asked for."""
        m = cls.__new__(cls)
        m._arrays, m._file, m.report = None, path, report
        return m

    def _load(self) -> Tuple[np.ndarray, np.ndarray]:
        if self._arrays is None:
            loaded = Mesh.load(self._file)
            self._arrays = (loaded.vertices, loaded.faces)
        return self._arrays

    @property
    def vertices(self) -> np.ndarray:
        """(N, 3) float64, mm."""
        return self._load()[0]

    @vertices.setter
    def vertices(self, v: Any) -> None:
        self._arrays = (np.ascontiguousarray(v, dtype=np.float64), self.faces)

    @property
    def faces(self) -> np.ndarray:
        """(M, 3) uint32 vertex indices, wound outward."""
        return self._load()[1]

    @faces.setter
    def faces(self, f: Any) -> None:
        self._arrays = (self.vertices, np.ascontiguousarray(f, dtype=np.uint32))

    @classmethod
    def load(cls, path: Union[str, os.PathLike]) -> "Mesh":
        """Reads a mesh file (.stl, .obj, .off, .ply, .3mf), corners welded."""
        try:
            v, f = _latvox.read_mesh(os.fspath(path))
        except _latvox.Failure as e:
            raise _raised(e) from None
        return cls(v, f)

    @property
    def volume(self) -> float:
        """Enclosed volume, mm³ (divergence theorem; exact for a closed, outward mesh)."""
        t = self.vertices[self.faces]
        return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6.0)

    def save(self, path: Union[str, os.PathLike]) -> None:
        """Writes the mesh in the format its extension names (.stl, .3mf, .obj, .off, .ply, or
        .vdb for its level set), atomically: the file appears whole or not at all."""
        try:
            _latvox.save_mesh(self.vertices, self.faces, os.fspath(path))
        except _latvox.Failure as e:
            raise _raised(e) from None

    def to_trimesh(self):
        """The mesh as a ``trimesh.Trimesh`` (trimesh must be installed), vertices as they are."""
        import trimesh

        return trimesh.Trimesh(vertices=self.vertices, faces=self.faces, process=False)

    def __repr__(self) -> str:
        if self._arrays is None:
            return f"latvox.Mesh(written to {self._file!r})"
        return f"latvox.Mesh({len(self.vertices)} vertices, {len(self.faces)} faces)"


class Layer:
    """One layer of a slice: its height ``z`` (mm along the build direction) and its
    ``polygons``, each a (K, 2) float64 array of a closed contour's corners (outer contours
    counter-clockwise, holes clockwise)."""

    def __init__(self, z: float, polygons: List[np.ndarray]):
        self.z = z
        self.polygons = polygons

    def __repr__(self) -> str:
        return f"latvox.Layer(z={self.z}, {len(self.polygons)} polygons)"


class Density:
    """A density field from :func:`topopt`: ``array`` (nely, nelx) or (nelz, nely, nelx) float64
    in [0, 1], and the optimisation's ``report``. :func:`interpret` takes it as its input."""

    def __init__(self, array: np.ndarray, report: Dict[str, Any]):
        self.array = array
        self.report = report

    def __repr__(self) -> str:
        return f"latvox.Density({self.array.shape})"


class Part:
    """A part file (``--save-part``'s TOML): ``command`` (the command that makes it), ``settings``
    (its options, as the file holds them) and ``path``. ``make(**overrides)`` makes it, as
    ``latvox COMMAND --part FILE [overrides]`` does."""

    def __init__(self, path: Union[str, os.PathLike]):
        self.path = os.path.abspath(os.fspath(path))
        try:
            command, settings = _latvox.read_part(self.path)
        except _latvox.Failure as e:
            raise _raised(e) from None
        self.command: str = command
        self.settings: Dict[str, Any] = json.loads(settings)

    def make(self, **overrides: Any) -> Mesh:
        """Makes the part (a :class:`Mesh`), with ``overrides`` replacing the file's settings."""
        return _COMMANDS[self.command](part=self.path, **overrides)

    def __repr__(self) -> str:
        return f"latvox.Part({self.command!r}, {self.path!r})"


def load_part(path: Union[str, os.PathLike]) -> Part:
    """Reads a part file (``latvox tpms … --save-part part.toml``); ``.make()`` makes it."""
    return Part(path)


_OPTIONS: Dict[str, Dict[str, Dict[str, Any]]] = {}


def _options(command: str) -> Dict[str, Dict[str, Any]]:
    if command not in _OPTIONS:
        opts: Dict[str, Dict[str, Any]] = {}
        for o in _latvox.options(command):
            name = o["name"]
            if name[0].isdigit():
                name = "two_" + name[1:] if name[0] == "2" else "_" + name
            # A positional argument and an option may share a name: the positional is first.
            key = name if name not in opts else name + "_option"
            opts[key] = o
        _OPTIONS[command] = opts
    return _OPTIONS[command]


def _scalar(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (os.PathLike,)):
        return os.fspath(v)
    if isinstance(v, (np.generic,)):
        v = v.item()
    return str(v)


def _mesh_file(m: Any, folder: str, name: str) -> str:
    """A mesh given as a path, a Mesh, a (vertices, faces) pair or a trimesh.Trimesh, as a file."""
    if isinstance(m, (str, os.PathLike)):
        return os.fspath(m)
    if isinstance(m, Mesh):
        mesh = m
    elif isinstance(m, tuple) and len(m) == 2:
        mesh = Mesh(m[0], m[1])
    elif hasattr(m, "vertices") and hasattr(m, "faces"):
        mesh = Mesh(np.asarray(m.vertices), np.asarray(m.faces))
    else:
        raise InputError(
            f"{name}: a mesh is a path, a latvox.Mesh, a (vertices, faces) pair or a "
            f"trimesh.Trimesh, got {type(m).__name__}"
        )
    path = os.path.join(folder, name + ".ply")
    mesh.save(path)
    return path


def _value(v: Any, folder: str, name: str) -> str:
    if isinstance(v, Density):
        v = v.array
    if isinstance(v, np.ndarray):
        path = os.path.join(folder, name + ".npy")
        np.save(path, v)
        return path
    if isinstance(v, (tuple, list)):
        return ",".join(_scalar(x) for x in v)
    return _scalar(v)


def _argv(command: str, given: Dict[str, Any], folder: str, meshes: Sequence[str] = ()) -> List[str]:
    opts = _options(command)
    args: List[str] = []
    positional: List[str] = []
    for key, v in given.items():
        o = opts.get(key)
        if o is None:
            close = difflib.get_close_matches(key, list(opts), n=1)
            hint = f" (did you mean {close[0]}?)" if close else ""
            raise InputError(f"{command}: unknown option '{key}'{hint}", {"setting": key})
        if v is None:
            continue
        if o["flag"]:
            if v is True:
                args.append("--" + o["long"])
            elif v is not False:
                raise InputError(
                    f"{command}: {key} is True or False, got {v!r}", {"setting": o["long"]}
                )
            continue
        values = v if o["multiple"] and isinstance(v, list) else [v]
        for x in values:
            text = (
                _mesh_file(x, folder, key)
                if key in meshes
                else _value(x, folder, key)
            )
            if o["long"] is None:
                positional.append(text)
            else:
                args.append(f"--{o['long']}={text}")
    return positional + args if positional else args


def _progress(progress: Union[bool, Callable[[str], Any], None]):
    if progress is None or progress is False:
        return None
    if callable(progress):
        return progress
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return None
    bar = tqdm(total=None, bar_format="{desc} {elapsed}", leave=False)

    def stage(name: str) -> None:
        bar.set_description_str(name)
        bar.update(0)

    stage.bar = bar  # type: ignore[attr-defined]
    return stage


def _run(
    command: str,
    given: Dict[str, Any],
    *,
    meshes: Sequence[str] = (),
    output: Optional[str] = None,
    strict: bool = False,
    progress: Union[bool, Callable[[str], Any], None] = None,
    threads: Optional[int] = None,
    keep: bool = True,
    read: Callable[[str, List[Tuple[str, np.ndarray, np.ndarray]], Dict[str, Any], bool], Any],
) -> Any:
    """Runs `command` with the keyword arguments `given`; `output`: the file it writes to,
    in a temporary folder, unless the caller names one; `read` makes the result of the written
    output's path, the meshes kept, the report and whether the caller named the output (and so
    it stays)."""
    opts = _options(command)
    with tempfile.TemporaryDirectory(prefix="latvox-") as folder:
        given = dict(given)
        # Outputs latvox names itself are kept in memory; one the caller names is written.
        named = output is not None and given.get("output") is not None
        keep = keep and output is not None and not named
        if output is not None and given.get("output") is None:
            given["output"] = os.path.join(folder, output)
        if "report" in opts and given.get("report") is None:
            given["report"] = os.path.join(folder, "report.json")
        args = _argv(command, given, folder, meshes)
        cb = _progress(progress)
        try:
            code, kept = _latvox.run(command, args, threads, cb, keep)
        except _latvox.Failure as e:
            raise _raised(e) from None
        finally:
            bar = getattr(cb, "bar", None)
            if bar is not None:
                bar.close()
        report: Dict[str, Any] = {}
        if "report" in given and os.path.exists(given["report"]):
            with open(given["report"]) as r:
                report = json.load(r)
        result = read(given.get("output", ""), kept, report, named)
    if code != 0 and strict:
        raise DefectError(
            f"{command}: the result has defects (see its report)", result, report
        )
    return result


def _mesh_result(path: str, kept, report, named: bool) -> Mesh:
    for p, v, f in kept:
        if os.path.abspath(p) == os.path.abspath(path):
            return Mesh(v, f, report)
    if kept:
        _, v, f = kept[0]
        return Mesh(v, f, report)
    if named:
        # The caller's file: read only if its arrays are asked for.
        return Mesh._written(os.fspath(path), report)
    m = Mesh.load(path)
    m.report = report
    return m


def tpms(*, strict: bool = False, progress=None, threads: Optional[int] = None, **options) -> Mesh:
    return _run("tpms", options, output="part.stl", strict=strict, progress=progress,
                threads=threads, read=_mesh_result)


def strut(*, strict: bool = False, progress=None, threads: Optional[int] = None, **options) -> Mesh:
    return _run("strut", options, output="part.stl", strict=strict, progress=progress,
                threads=threads, read=_mesh_result)


def voronoi(*, strict: bool = False, progress=None, threads: Optional[int] = None,
            **options) -> Mesh:
    return _run("voronoi", options, output="part.stl", strict=strict, progress=progress,
                threads=threads, read=_mesh_result)


def fill(input: Any = None, *, strict: bool = False, progress=None,
         threads: Optional[int] = None, **options) -> Mesh:
    if input is not None:
        options["input"] = input
    return _run("fill", options, meshes=("input", "input_option"), output="part.stl",
                strict=strict, progress=progress, threads=threads, read=_mesh_result)


def fgm(*, strict: bool = False, progress=None, threads: Optional[int] = None, **options) -> Mesh:
    return _run("fgm", options, meshes=("mesh",), output="part.stl", strict=strict,
                progress=progress, threads=threads, read=_mesh_result)


def interpret(input: Any, *, strict: bool = False, progress=None,
              threads: Optional[int] = None, **options) -> Mesh:
    options["input"] = input
    return _run("interpret", options, output="part.stl", strict=strict, progress=progress,
                threads=threads, read=_mesh_result)


def topopt(*, strict: bool = False, progress=None, threads: Optional[int] = None,
           **options) -> Density:
    def read(path, kept, report, named):
        return Density(np.load(path), report)

    return _run("topopt", options, output="densities.npy", strict=strict, progress=progress,
                threads=threads, read=read)


def homogenize(*, progress=None, threads: Optional[int] = None, **options) -> Dict[str, Any]:
    return _run("homogenize", options, progress=progress, threads=threads,
                read=lambda path, kept, report, named: report)


def check(mesh: Any, *, strict: bool = False, progress=None, threads: Optional[int] = None,
          **options) -> Dict[str, Any]:
    options["file"] = mesh
    return _run("check", options, meshes=("file",), strict=strict, progress=progress,
                threads=threads, read=lambda path, kept, report, named: report)


def repair(mesh: Any, *, strict: bool = False, progress=None, threads: Optional[int] = None,
           **options) -> Mesh:
    options["input"] = mesh
    # Repair checks the file it wrote, as the next program will read it: written, then read.
    return _run("repair", options, meshes=("input",), output="repaired.stl", strict=strict,
                progress=progress, threads=threads, keep=False, read=_mesh_result)


def _read_cli(path: str) -> List[Layer]:
    """The layers of an ASCII Common Layer Interface file."""
    units = 1.0
    layers: List[Layer] = []
    with open(path) as f:
        text = f.read()
    header, _, geometry = text.partition("$$GEOMETRYSTART")
    for line in header.splitlines():
        if line.startswith("$$UNITS/"):
            units = float(line.split("/", 1)[1])
    for line in geometry.splitlines():
        line = line.strip()
        if line.startswith("$$LAYER/"):
            layers.append(Layer(float(line.split("/", 1)[1]) * units, []))
        elif line.startswith("$$POLYLINE/") and layers:
            nums = [float(x) for x in line.split("/", 1)[1].split(",")]
            n = int(nums[2])
            pts = np.array(nums[3 : 3 + 2 * n], dtype=np.float64).reshape(n, 2) * units
            if n > 1 and np.array_equal(pts[0], pts[-1]):
                pts = pts[:-1]
            layers[-1].polygons.append(pts)
    return layers


def slice(mesh: Any, *, strict: bool = False, progress=None, threads: Optional[int] = None,
          **options) -> List[Layer]:
    options["input"] = mesh
    meshes = () if isinstance(mesh, (str, os.PathLike)) else ("input",)
    return _run("slice", options, meshes=meshes, output="layers.cli", strict=strict,
                progress=progress, threads=threads,
                read=lambda path, kept, report, named: _read_cli(path))


def render(part: Any, width: int = 800, height: int = 600, *, progress=None,
           threads: Optional[int] = None, **options) -> np.ndarray:
    if isinstance(part, Part):
        part = part.path
    options.update(input=part, width=width, height=height)
    meshes = () if isinstance(part, (str, os.PathLike)) else ("input",)

    def read(path, kept, report, named):
        return _latvox.read_png(path)

    return _run("render", options, meshes=meshes, output="view.png", progress=progress,
                threads=threads, read=read)


_COMMANDS: Dict[str, Callable[..., Any]] = {
    "tpms": tpms,
    "strut": strut,
    "voronoi": voronoi,
    "fill": fill,
    "fgm": fgm,
    "interpret": interpret,
    "topopt": topopt,
    "homogenize": homogenize,
    "check": check,
    "repair": repair,
    "slice": slice,
    "render": render,
}

_CALLS = {
    "tpms": "tpms(**options)",
    "strut": "strut(**options)",
    "voronoi": "voronoi(**options)",
    "fill": "fill(input, **options)",
    "fgm": "fgm(**options)",
    "interpret": "interpret(input, **options)",
    "topopt": "topopt(**options)",
    "homogenize": "homogenize(**options)",
    "check": "check(mesh, **options)",
    "repair": "repair(mesh, **options)",
    "slice": "slice(mesh, **options)",
    "render": "render(part, width=800, height=600, **options)",
}

_RETURNS = {
    "tpms": "a Mesh (its report as --report writes it)",
    "strut": "a Mesh (its report as --report writes it)",
    "voronoi": "a Mesh (its report as --report writes it)",
    "fill": "a Mesh (its report as --report writes it)",
    "fgm": "a Mesh (its report as --report writes it)",
    "interpret": "a Mesh (its report as --report writes it)",
    "topopt": "a Density: the densities as an array, and the report",
    "homogenize": "the report, a dict: stiffness (6 × 6, Voigt order), compliance, constants",
    "check": "the report, a dict (the fields of `latvox check --json`)",
    "repair": "the repaired Mesh (its report as --report writes it)",
    "slice": "a list of Layer: z and the polygons, (K, 2) arrays",
    "render": "the picture, an (H, W, 3) uint8 array",
}


def _doc(name: str) -> str:
    return (
        f"latvox.{_CALLS[name]} -> {_RETURNS[name]}\n\n"
        "Keyword arguments are the command line's options, dashes as underscores (cell_size=5.0 "
        "for --cell-size 5); per-axis options take tuples (cells=(4, 4, 2)); flags take True; "
        "fields take an expression, a NumPy array or a file name. Output files are kept in memory "
        "unless output= names one. Also: strict=True (raise DefectError where the command line "
        "exits with 1), progress=True or a function, threads=N.\n\n"
        "The command line's help:\n\n"
        + _latvox.help(name)
    )


for _name, _fn in _COMMANDS.items():
    _fn.__doc__ = _doc(_name)
del _name, _fn
