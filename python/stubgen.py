"""Writes latvox/__init__.pyi, the typed signatures of the package, from the commands' own
definitions (their options, defaults and help), so that IDEs and mypy see every keyword argument.

    python3 python/stubgen.py      # after changing a command's options; a test checks it is current
"""

import sys
import textwrap
from pathlib import Path

HERE = Path(__file__).resolve().parent
# The installed package (pip install .), not the sources beside this script.
sys.path = [p for p in sys.path if Path(p or ".").resolve() != HERE]

from latvox import _latvox  # noqa: E402

# name: (positional parameters, return type)
FUNCTIONS = {
    "tpms": ("", "Mesh"),
    "strut": ("", "Mesh"),
    "voronoi": ("", "Mesh"),
    "fill": ("input: MeshLike | None = None, ", "Mesh"),
    "fgm": ("", "Mesh"),
    "interpret": ("input: Union[str, os.PathLike, np.ndarray, Density], ", "Mesh"),
    "topopt": ("", "Density"),
    "homogenize": ("", "Dict[str, Any]"),
    "check": ("mesh: MeshLike, ", "Dict[str, Any]"),
    "repair": ("mesh: MeshLike, ", "Mesh"),
    "slice": ("mesh: MeshLike, ", "List[Layer]"),
    "render": ("part: MeshLike, width: int = 800, height: int = 600, ", "np.ndarray"),
}

# Options the functions fill in themselves, or that the command line alone has.
HIDDEN = {"json", "input_option"}

HEADER = '''\
# Typed signatures of latvox's Python package. Written by python/stubgen.py from the commands'
# definitions: do not edit by hand.
from __future__ import annotations

import os
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

MeshLike = Union[str, os.PathLike, "Mesh", Tuple[np.ndarray, np.ndarray], Any]
Value = Union[str, float, int, os.PathLike, Sequence[float], np.ndarray]
Progress = Union[bool, Callable[[str], Any], None]

class Error(Exception): ...

class InputError(Error, ValueError):
    setting: Optional[str]
    value: Optional[float]
    min: Optional[float]
    max: Optional[float]
    requested: Optional[int]
    needed: Optional[int]
    path: Optional[str]
    def __init__(self, message: str, data: Optional[Dict[str, Any]] = ...) -> None: ...

class DefectError(Error):
    result: Any
    report: Dict[str, Any]

class BackendError(Error, RuntimeError): ...

class Mesh:
    """A triangle mesh: vertices (N, 3) float64 mm, faces (M, 3) uint32, and its report."""
    vertices: np.ndarray
    faces: np.ndarray
    report: Dict[str, Any]
    def __init__(self, vertices: Any, faces: Any, report: Optional[Dict[str, Any]] = ...) -> None: ...
    @classmethod
    def load(cls, path: Union[str, os.PathLike]) -> Mesh: ...
    @property
    def volume(self) -> float: ...
    def save(self, path: Union[str, os.PathLike]) -> None: ...
    def to_trimesh(self) -> Any: ...

class Layer:
    """One layer of a slice: z (mm) and its polygons, each a (K, 2) float64 array."""
    z: float
    polygons: List[np.ndarray]

class Density:
    """A density field from topopt: array and report."""
    array: np.ndarray
    report: Dict[str, Any]

class Part:
    """A part file: its command, settings and path; make() makes it."""
    path: str
    command: str
    settings: Dict[str, Any]
    def __init__(self, path: Union[str, os.PathLike]) -> None: ...
    def make(self, **overrides: Any) -> Mesh: ...

def load_part(path: Union[str, os.PathLike]) -> Part: ...
'''


def keyword(o) -> str:
    name = o["name"]
    if name[0].isdigit():
        name = "two_" + name[1:]
    if o["flag"]:
        return f"{name}: bool = False"
    kind = "Union[Value, List[Value]]" if o["multiple"] else "Value"
    return f"{name}: Optional[{kind}] = None"


def doc(o) -> str:
    name = o["name"]
    default = f" (default: {o['default']})" if o["default"] is not None else ""
    values = f" [{', '.join(o['values'])}]" if o["values"] else ""
    first = " ".join(o["help"].split("\n\n")[0].split())
    return f"{name}: {first}{default}{values}"


def function(name: str) -> str:
    positional, returns = FUNCTIONS[name]
    opts = [o for o in _latvox.options(name) if o["long"] is not None and o["name"] not in HIDDEN]
    if name in ("render",):
        opts = [o for o in opts if o["name"] not in ("width", "height")]
    kw = ",\n    ".join([keyword(o) for o in opts]
                        + ["strict: bool = False", "progress: Progress = None",
                           "threads: Optional[int] = None"])
    about = dict(_latvox.commands())[name]
    lines = [about + "."] + [""] + [doc(o) for o in opts]
    body = "\n".join(textwrap.fill(l, 96, subsequent_indent="    ") if l else "" for l in lines)
    body = textwrap.indent(body, "    ")
    return (f"def {name}(\n    {positional}*,\n    {kw},\n) -> {returns}:\n"
            f'    """\n{body}\n    """\n    ...\n')


def stub() -> str:
    return HEADER + "".join("\n" + function(n) for n in FUNCTIONS)


if __name__ == "__main__":
    (HERE / "latvox" / "__init__.pyi").write_text(stub())
    (HERE / "latvox" / "py.typed").write_text("")
