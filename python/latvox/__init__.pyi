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

def tpms(
    *,
    type: Optional[Value] = None,
    structure: Optional[Value] = None,
    side: Optional[Value] = None,
    density: Optional[Value] = None,
    density_grade: Optional[Value] = None,
    density_field: Optional[Value] = None,
    stiffness_field: Optional[Value] = None,
    clamp: bool = False,
    blend_to: Optional[Value] = None,
    blend_field: Optional[Value] = None,
    cell_map: Optional[Value] = None,
    layers: Optional[Value] = None,
    cell_size_grade: Optional[Value] = None,
    cell_size_field: Optional[Value] = None,
    bore: Optional[Value] = None,
    cells: Optional[Value] = None,
    cell_size: Optional[Value] = None,
    size: Optional[Value] = None,
    origin: Optional[Value] = None,
    allow_islands: bool = False,
    resolution: Optional[Value] = None,
    fixed_resolution: bool = False,
    adaptivity: Optional[Value] = None,
    tolerance: Optional[Value] = None,
    output: Optional[Value] = None,
    ascii: bool = False,
    report: Optional[Value] = None,
    verify: Optional[Value] = None,
    no_self_intersection_check: bool = False,
    no_instancing: bool = False,
    memory: Optional[Value] = None,
    tile: Optional[Value] = None,
    keep_fragments: bool = False,
    save_part: Optional[Value] = None,
    part: Optional[Value] = None,
    strict: bool = False,
    progress: Progress = None,
    threads: Optional[int] = None,
) -> Mesh:
    """
    Generate a closed TPMS lattice at an exact volume fraction.

    type: Surface: p, gyroid (g), d, iwp, s, frd, neovius (n), lidinoid (l), split-p (default:
        gyroid)
    structure: Solid side: net (F ≤ t) or sheet (|F| ≤ t) (default: net)
    side: Which labyrinth of a net is solid: first (F ≤ t) or other (−F ≤ t, the complementary
        labyrinth, for nets whose two sides differ: F-RD, I-WP, Neovius, …) (default: first) [first,
        other]
    density: Target volume fraction of solid, in (0, 1) (default: 0.3)
    density_grade: Grade the density linearly along an axis across the box: AXIS:A:B (as z:0.1:0.4);
        every whole cell meets the grade at its centre within ±0.01
    density_field: Grade the density by a field: an expression in x, y, z (mm; as "0.15 +
        0.1*sin(PI*x/20)"; for fill also d, the depth below the skin), a .npy array of shape (NX,
        NY, NZ) sampled over the box, corners on its corners, or a .vdb's float grid (named density,
        or the first) in the part's coordinates, read between its voxels' centres
    stiffness_field: Grade by stiffness: a field (as --density-field takes) of the Young's modulus
        wanted, relative to the solid's (E/Es, the mean along the axes); each point's density is the
        one at which the lattice's unit cell, homogenised (`latvox homogenize`), is that stiff. With
        --clamp, stiffnesses beyond those of the densities homogenised (TPMS: 0.05 or the least that
        holds together to 0.8; struts 0.03 to 0.6) take those densities
    clamp: Hold a density field to the type's feasible range instead of refusing it (reported)
    blend_to: Blend the type into a second one (p, gyroid, d, …) by --blend-field: the solid where
        (1 − w)·F/s + w·F₂/s₂ is below the level (s: each surface's RMS), each cell at its density
    blend_field: The weight w of --blend-to at each point, held to [0, 1]: AXIS:A:B (linear along x,
        y or z across the box, as x:0:1) or a field as --density-field takes
    cell_map: Wrap the cells around an axis or a centre. cylindrical: a tube about the z axis
        through --origin (its lower end's centre); --cells gives the cells around, through the wall
        and along the axis (12,1,4 by default), --cell-size the cell's size through the wall and
        along the axis (5 mm by default), --bore the inner radius; whole cells around, none cut at
        the seam. spherical: a shell about --origin made of a cube's six faces (a cubed sphere, no
        poles); --cells N gives the cells along each face's edge at the bore (4 by default),
        --layers the cells through the wall (1), --cell-size the cell's size through the wall (by
        default πR/2N, cubes at the faces' middles); every cell whole. Towards the cube's corners
        the cells are about half as wide: --resolution counts voxels across those [cylindrical,
        spherical]
    layers: Cells through the wall of a --cell-map spherical shell (1 by default)
    cell_size_grade: Grade the cell size along an axis: AXIS:A:B, cells A mm at the box's lower face
        growing to B mm at its upper one (as z:3:6), scaled a little so that whole cells span the
        box (the cell size along the other axes from --cell-size); no cell is torn
    cell_size_field: Size the cells by a field: the cell size in mm at each point, an expression in
        x, y, z (as "3 + 0.1*sqrt((x-20)^2 + (y-20)^2)"), a .npy array spanning the box or a .vdb's
        float grid. Every line of cells along an axis holds the same whole number of cells, each
        stretched to the field's size along the line; no cell is torn. Where the field varies across
        a line, the line's cells lean and keep its count (the report gives how far each axis' cells
        came from the field)
    bore: Inner radius of a --cell-map tube or shell, mm
    cells: Cells per axis: N or NX,NY,NZ
    cell_size: Cell size in mm: A or AX,AY,AZ
    size: Overall box size in mm (with --cells or --cell-size): S or SX,SY,SZ
    origin: Lower corner of the box in mm (lattice phase starts there) (default: 0,0,0)
    allow_islands: Build even when the solid falls apart into islands at this density
    resolution: Voxels per cell along the cell's shortest side (default: 32)
    fixed_resolution: Fail instead of raising the resolution when the lattice's members would be too
        thin for the voxels
    adaptivity: Kept for older scripts: simplify within this many voxels, 0 to 1 (0.5: half a
        voxel); --tolerance says it in millimetres and wins over it (default: 0)
    tolerance: Simplify the mesh: the largest distance allowed between it and the exact surface, mm,
        or auto. Flat regions get large triangles, curved ones small; every vertex stays on the
        surface, the density is kept, and the deviation is measured and reported. Without it the
        mesh is uniform (two triangles per voxel the surface crosses): its deviation is about half a
        voxel at the box's cut edges and where struts meet. auto keeps to that: half a voxel (cell /
        resolution / 2, 0.078 mm for 5 mm cells at 32), or the deviation measured on the uniform
        mesh where larger, with 7–30× fewer triangles. A tolerance under the uniform mesh's
        deviation meshes the part on voxels up to half as large first. The part is then meshed whole
        (not copied cell by cell, nor in tiles)
    output: Output mesh, in the format its extension names: .stl (binary, ASCII with --ascii) or
        .3mf, streamed to the file as it is made; .obj, .off or .ply (binary, ASCII with --ascii),
        written once the part is whole; .vdb, the part's level set at its voxels (OpenVDB, a grid
        named sdf) (default: lattice.stl)
    ascii: Write ASCII STL (or ASCII PLY) instead of binary
    report: Write a JSON report (settings, densities, mesh counts, checks, timings)
    verify: How the part is verified: full (closed, manifold, outward and no self-intersection,
        exact, on the whole written part), fast (no self-intersection search), none, or cgal (CGAL's
        own checks, an independent second opinion, several times slower) (default: full) [full,
        fast, none, cgal]
    no_self_intersection_check: The same as --verify fast
    no_instancing: Mesh the whole part at once instead of copying its periodic cells from a meshed
        3×3×3-cell template (slower, same solid; the whole part is then verified)
    memory: Memory budget while meshing, e.g. 2G or 512M: a part whose grid would not fit is meshed
        in tiles sized from it and streamed to the file (default 4G)
    tile: Mesh in tiles of this many voxels a side (a multiple of 8, at least 16), whatever the
        part's size; the tiled part is the same solid as the untiled one
    keep_fragments: Keep the pieces the box cuts loose from the lattice (by default they are
        removed, so that the part is one piece; the summary and report count them either way)
    save_part: Save the settings that define this part (all but where its files go) to a TOML part
        file, once the part is made
    part: Make the part a part file describes (options given here override the file's)
    """
    ...

def strut(
    *,
    cell: Optional[Value] = None,
    density: Optional[Value] = None,
    radius: Optional[Value] = None,
    density_grade: Optional[Value] = None,
    density_field: Optional[Value] = None,
    stiffness_field: Optional[Value] = None,
    clamp: bool = False,
    blend: Optional[Value] = None,
    beams: bool = False,
    cells: Optional[Value] = None,
    cell_size: Optional[Value] = None,
    size: Optional[Value] = None,
    origin: Optional[Value] = None,
    resolution: Optional[Value] = None,
    fixed_resolution: bool = False,
    adaptivity: Optional[Value] = None,
    tolerance: Optional[Value] = None,
    output: Optional[Value] = None,
    ascii: bool = False,
    report: Optional[Value] = None,
    verify: Optional[Value] = None,
    no_self_intersection_check: bool = False,
    no_instancing: bool = False,
    memory: Optional[Value] = None,
    tile: Optional[Value] = None,
    keep_fragments: bool = False,
    save_part: Optional[Value] = None,
    part: Optional[Value] = None,
    strict: bool = False,
    progress: Progress = None,
    threads: Optional[int] = None,
) -> Mesh:
    """
    Generate a closed strut (beam) lattice — BCC, octet, Kelvin or a cell of your own — at an exact
        volume fraction or strut radius.

    cell: Unit cell: a built-in name (sc, bcc, bccz, fcc, fccz, octet, kelvin, diamond, rhombic) or
        a cell file (.json: nodes, struts, optional radii) (default: bcc)
    density: Target volume fraction of solid, in (0, 1): the strut radius is found for it (0.2 when
        neither --density nor --radius is given)
    radius: Strut radius in mm (times each node's factor), instead of a density
    density_grade: Grade the density linearly along an axis across the box: AXIS:A:B (as z:0.1:0.4);
        every whole cell meets the grade at its centre within ±0.01
    density_field: Grade the density by a field: an expression in x, y, z (mm; as "0.15 +
        0.1*sin(PI*x/20)"; for fill also d, the depth below the skin), a .npy array of shape (NX,
        NY, NZ) sampled over the box, corners on its corners, or a .vdb's float grid (named density,
        or the first) in the part's coordinates, read between its voxels' centres
    stiffness_field: Grade by stiffness: a field (as --density-field takes) of the Young's modulus
        wanted, relative to the solid's (E/Es, the mean along the axes); each point's density is the
        one at which the lattice's unit cell, homogenised (`latvox homogenize`), is that stiff. With
        --clamp, stiffnesses beyond those of the densities homogenised (TPMS: 0.05 or the least that
        holds together to 0.8; struts 0.03 to 0.6) take those densities
    clamp: Hold a density field to the type's feasible range instead of refusing it (reported)
    blend: Fillet the joints: smooth minimum over this many mm (0: a sharp union) (default: 0)
    beams: Write the lattice as beams (3MF Beam Lattice extension: each strut a beam with its radii,
        the box a clipping mesh) instead of a mesh: kilobytes instead of gigabytes, for printers and
        tools that read beams. The output must be .3mf; joints cannot be blended
    cells: Cells per axis: N or NX,NY,NZ
    cell_size: Cell size in mm: A or AX,AY,AZ
    size: Overall box size in mm (with --cells or --cell-size): S or SX,SY,SZ
    origin: Lower corner of the box in mm (lattice phase starts there) (default: 0,0,0)
    resolution: Voxels per cell along the cell's shortest side (default: 32)
    fixed_resolution: Fail instead of raising the resolution when the lattice's members would be too
        thin for the voxels
    adaptivity: Kept for older scripts: simplify within this many voxels, 0 to 1 (0.5: half a
        voxel); --tolerance says it in millimetres and wins over it (default: 0)
    tolerance: Simplify the mesh: the largest distance allowed between it and the exact surface, mm,
        or auto. Flat regions get large triangles, curved ones small; every vertex stays on the
        surface, the density is kept, and the deviation is measured and reported. Without it the
        mesh is uniform (two triangles per voxel the surface crosses): its deviation is about half a
        voxel at the box's cut edges and where struts meet. auto keeps to that: half a voxel (cell /
        resolution / 2, 0.078 mm for 5 mm cells at 32), or the deviation measured on the uniform
        mesh where larger, with 7–30× fewer triangles. A tolerance under the uniform mesh's
        deviation meshes the part on voxels up to half as large first. The part is then meshed whole
        (not copied cell by cell, nor in tiles)
    output: Output mesh, in the format its extension names: .stl (binary, ASCII with --ascii) or
        .3mf, streamed to the file as it is made; .obj, .off or .ply (binary, ASCII with --ascii),
        written once the part is whole; .vdb, the part's level set at its voxels (OpenVDB, a grid
        named sdf) (default: lattice.stl)
    ascii: Write ASCII STL (or ASCII PLY) instead of binary
    report: Write a JSON report (settings, densities, mesh counts, checks, timings)
    verify: How the part is verified: full (closed, manifold, outward and no self-intersection,
        exact, on the whole written part), fast (no self-intersection search), none, or cgal (CGAL's
        own checks, an independent second opinion, several times slower) (default: full) [full,
        fast, none, cgal]
    no_self_intersection_check: The same as --verify fast
    no_instancing: Mesh the whole part at once instead of copying its periodic cells from a meshed
        3×3×3-cell template (slower, same solid; the whole part is then verified)
    memory: Memory budget while meshing, e.g. 2G or 512M: a part whose grid would not fit is meshed
        in tiles sized from it and streamed to the file (default 4G)
    tile: Mesh in tiles of this many voxels a side (a multiple of 8, at least 16), whatever the
        part's size; the tiled part is the same solid as the untiled one
    keep_fragments: Keep the pieces the box cuts loose from the lattice (by default they are
        removed, so that the part is one piece; the summary and report count them either way)
    save_part: Save the settings that define this part (all but where its files go) to a TOML part
        file, once the part is made
    part: Make the part a part file describes (options given here override the file's)
    """
    ...

def voronoi(
    *,
    structure: Optional[Value] = None,
    spacing: Optional[Value] = None,
    spacing_field: Optional[Value] = None,
    seed: Optional[Value] = None,
    regularity: Optional[Value] = None,
    seeds_in: Optional[Value] = None,
    seeds_out: Optional[Value] = None,
    periodic: Optional[Value] = None,
    cell_out: Optional[Value] = None,
    density: Optional[Value] = None,
    density_grade: Optional[Value] = None,
    density_field: Optional[Value] = None,
    stiffness_field: Optional[Value] = None,
    clamp: bool = False,
    radius: Optional[Value] = None,
    thickness: Optional[Value] = None,
    pores: Optional[Value] = None,
    beams: bool = False,
    size: Optional[Value] = None,
    origin: Optional[Value] = None,
    resolution: Optional[Value] = None,
    fixed_resolution: bool = False,
    adaptivity: Optional[Value] = None,
    tolerance: Optional[Value] = None,
    output: Optional[Value] = None,
    ascii: bool = False,
    report: Optional[Value] = None,
    verify: Optional[Value] = None,
    no_self_intersection_check: bool = False,
    no_instancing: bool = False,
    memory: Optional[Value] = None,
    tile: Optional[Value] = None,
    keep_fragments: bool = False,
    save_part: Optional[Value] = None,
    part: Optional[Value] = None,
    strict: bool = False,
    progress: Progress = None,
    threads: Optional[int] = None,
) -> Mesh:
    """
    Generate a Voronoi foam — struts along the edges or walls along the faces of a random (or
        graded, or partly regular) Voronoi diagram — at an exact volume fraction.

    structure: Struts along the Voronoi edges (net) or walls along its faces (sheet) (default: net)
        [net, sheet]
    spacing: Mean spacing of the seeds, mm: the edge of the mean cell (default: 3)
    spacing_field: A spacing that varies through the box (instead of --spacing): an expression in x,
        y, z (mm), a .npy array spanning the box, or a .vdb grid
    seed: The random generator's seed: the same seed gives the same foam, byte for byte (default: 1)
    regularity: Move the seeds toward the body-centred cubic lattice: 0 random, 1 the Kelvin foam
        (default: 0)
    seeds_in: Your own seeds: a CSV file of x,y,z per line, mm (they should fill the box and a
        margin of a cell or two round it)
    seeds_out: Write the seeds used (box and margin; a periodic foam's cell) to a CSV file
    periodic: Make a foam that repeats with a cube of this edge, mm (at least two spacings), from
        the box's lower corner: random inside the cell, seamless across cells, meshed once and
        copied through a large box
    cell_out: Write a periodic net's cell as a strut cell (JSON: nodes in unit-cell coordinates,
        struts), for `strut --cell`, `fill --cell` and `homogenize --cell`
    density: Target volume fraction of solid, in (0, 1) (0.15 when no size is given)
    density_grade: Grade the density linearly along an axis across the box: AXIS:A:B (as z:0.1:0.4);
        every whole cell meets the grade at its centre within ±0.01
    density_field: Grade the density by a field: an expression in x, y, z (mm; as "0.15 +
        0.1*sin(PI*x/20)"; for fill also d, the depth below the skin), a .npy array of shape (NX,
        NY, NZ) sampled over the box, corners on its corners, or a .vdb's float grid (named density,
        or the first) in the part's coordinates, read between its voxels' centres
    stiffness_field: Grade by stiffness: a field (as --density-field takes) of the Young's modulus
        wanted, relative to the solid's (E/Es, the mean along the axes); each point's density is the
        one at which the lattice's unit cell, homogenised (`latvox homogenize`), is that stiff. With
        --clamp, stiffnesses beyond those of the densities homogenised (TPMS: 0.05 or the least that
        holds together to 0.8; struts 0.03 to 0.6) take those densities
    clamp: Hold a density field to the type's feasible range instead of refusing it (reported)
    radius: Strut radius of a net, mm, instead of a density
    thickness: Wall thickness of a sheet, mm, instead of a density
    pores: Open a sheet's cells: a round pore through the middle of each wall, this fraction of the
        wall's inradius (0 to 1; walls too small for a pore two voxels across keep none) (default:
        0)
    beams: Write the net as beams (3MF Beam Lattice extension: each Voronoi edge a beam of the
        radius, the box a clipping mesh) instead of a mesh. The output must be .3mf
    size: Box size in mm: S or SX,SY,SZ (default: 20)
    origin: Lower corner of the box in mm (default: 0,0,0)
    resolution: Voxels per cell along the cell's shortest side (default: 32)
    fixed_resolution: Fail instead of raising the resolution when the lattice's members would be too
        thin for the voxels
    adaptivity: Kept for older scripts: simplify within this many voxels, 0 to 1 (0.5: half a
        voxel); --tolerance says it in millimetres and wins over it (default: 0)
    tolerance: Simplify the mesh: the largest distance allowed between it and the exact surface, mm,
        or auto. Flat regions get large triangles, curved ones small; every vertex stays on the
        surface, the density is kept, and the deviation is measured and reported. Without it the
        mesh is uniform (two triangles per voxel the surface crosses): its deviation is about half a
        voxel at the box's cut edges and where struts meet. auto keeps to that: half a voxel (cell /
        resolution / 2, 0.078 mm for 5 mm cells at 32), or the deviation measured on the uniform
        mesh where larger, with 7–30× fewer triangles. A tolerance under the uniform mesh's
        deviation meshes the part on voxels up to half as large first. The part is then meshed whole
        (not copied cell by cell, nor in tiles)
    output: Output mesh, in the format its extension names: .stl (binary, ASCII with --ascii) or
        .3mf, streamed to the file as it is made; .obj, .off or .ply (binary, ASCII with --ascii),
        written once the part is whole; .vdb, the part's level set at its voxels (OpenVDB, a grid
        named sdf) (default: lattice.stl)
    ascii: Write ASCII STL (or ASCII PLY) instead of binary
    report: Write a JSON report (settings, densities, mesh counts, checks, timings)
    verify: How the part is verified: full (closed, manifold, outward and no self-intersection,
        exact, on the whole written part), fast (no self-intersection search), none, or cgal (CGAL's
        own checks, an independent second opinion, several times slower) (default: full) [full,
        fast, none, cgal]
    no_self_intersection_check: The same as --verify fast
    no_instancing: Mesh the whole part at once instead of copying its periodic cells from a meshed
        3×3×3-cell template (slower, same solid; the whole part is then verified)
    memory: Memory budget while meshing, e.g. 2G or 512M: a part whose grid would not fit is meshed
        in tiles sized from it and streamed to the file (default 4G)
    tile: Mesh in tiles of this many voxels a side (a multiple of 8, at least 16), whatever the
        part's size; the tiled part is the same solid as the untiled one
    keep_fragments: Keep the pieces the box cuts loose from the lattice (by default they are
        removed, so that the part is one piece; the summary and report count them either way)
    save_part: Save the settings that define this part (all but where its files go) to a TOML part
        file, once the part is made
    part: Make the part a part file describes (options given here override the file's)
    """
    ...

def fill(
    input: MeshLike | None = None, *,
    input: Optional[Value] = None,
    skin: Optional[Value] = None,
    no_skin: bool = False,
    lattice: Optional[Value] = None,
    spacing: Optional[Value] = None,
    seed: Optional[Value] = None,
    regularity: Optional[Value] = None,
    structure: Optional[Value] = None,
    cell_size: Optional[Value] = None,
    density: Optional[Value] = None,
    density_grade: Optional[Value] = None,
    density_field: Optional[Value] = None,
    stiffness_field: Optional[Value] = None,
    clamp: bool = False,
    blend: Optional[Value] = None,
    drain: Optional[Value] = None,
    keep: Optional[Union[Value, List[Value]]] = None,
    resolution: Optional[Value] = None,
    fixed_resolution: bool = False,
    adaptivity: Optional[Value] = None,
    tolerance: Optional[Value] = None,
    output: Optional[Value] = None,
    ascii: bool = False,
    report: Optional[Value] = None,
    verify: Optional[Value] = None,
    no_self_intersection_check: bool = False,
    no_instancing: bool = False,
    memory: Optional[Value] = None,
    tile: Optional[Value] = None,
    keep_fragments: bool = False,
    save_part: Optional[Value] = None,
    part: Optional[Value] = None,
    strict: bool = False,
    progress: Progress = None,
    threads: Optional[int] = None,
) -> Mesh:
    """
    Fill a part with a lattice: a solid skin of the part's shape, its core a TPMS or strut lattice
        at an exact density, solids kept whole where asked.

    input: The part to fill, as a part file gives it (the PART argument overrides it)
    skin: Thickness of the solid skin kept inside the part's surface, mm (default: 1)
    no_skin: No skin: the lattice cut by the part's surface (an open-cell part)
    lattice: The lattice: a TPMS (p, gyroid, d, iwp, s, frd, neovius, lidinoid, split-p), a strut
        cell (sc, bcc, bccz, fcc, fccz, octet, kelvin, diamond, rhombic), a strut cell file (.json),
        or voronoi (a random Voronoi net that repeats with the cell) (default: gyroid)
    spacing: For a Voronoi lattice: the mean spacing of its seeds, mm (the cell holds about
        cell³/spacing³ of them; a quarter of the cell when not given)
    seed: For a Voronoi lattice: the random generator's seed
    regularity: For a Voronoi lattice: move its seeds toward the body-centred cubic lattice, 0
        random to 1 the Kelvin foam
    structure: For a TPMS lattice: net (F ≤ t) or sheet (|F| ≤ t) (default: net)
    cell_size: Cell size in mm: A or AX,AY,AZ (cells start at the lower corner of the part's box)
        (default: 5)
    density: The lattice's volume fraction in the region it fills, in (0, 1) (default: 0.2)
    density_grade: Grade the density linearly along an axis across the box: AXIS:A:B (as z:0.1:0.4);
        every whole cell meets the grade at its centre within ±0.01
    density_field: Grade the density by a field: an expression in x, y, z (mm; as "0.15 +
        0.1*sin(PI*x/20)"; for fill also d, the depth below the skin), a .npy array of shape (NX,
        NY, NZ) sampled over the box, corners on its corners, or a .vdb's float grid (named density,
        or the first) in the part's coordinates, read between its voxels' centres
    stiffness_field: Grade by stiffness: a field (as --density-field takes) of the Young's modulus
        wanted, relative to the solid's (E/Es, the mean along the axes); each point's density is the
        one at which the lattice's unit cell, homogenised (`latvox homogenize`), is that stiff. With
        --clamp, stiffnesses beyond those of the densities homogenised (TPMS: 0.05 or the least that
        holds together to 0.8; struts 0.03 to 0.6) take those densities
    clamp: Hold a density field to the type's feasible range instead of refusing it (reported)
    blend: Fillet the lattice into the skin (and struts at their joints): smooth minimum over this
        many mm (0: a sharp union) (default: 0)
    drain: Drain holes of this diameter, mm, through the skin at the part's lowest and highest facet
        (along z), so that powder or resin can leave the lattice's void, which a skin closes
    keep: A solid kept whole (a boss, a flange), unioned with the filled part; repeat for more
    resolution: Voxels per cell along the cell's shortest side (default: 32)
    fixed_resolution: Fail instead of raising the resolution when the lattice's members would be too
        thin for the voxels
    adaptivity: Kept for older scripts: simplify within this many voxels, 0 to 1 (0.5: half a
        voxel); --tolerance says it in millimetres and wins over it (default: 0)
    tolerance: Simplify the mesh: the largest distance allowed between it and the exact surface, mm,
        or auto. Flat regions get large triangles, curved ones small; every vertex stays on the
        surface, the density is kept, and the deviation is measured and reported. Without it the
        mesh is uniform (two triangles per voxel the surface crosses): its deviation is about half a
        voxel at the box's cut edges and where struts meet. auto keeps to that: half a voxel (cell /
        resolution / 2, 0.078 mm for 5 mm cells at 32), or the deviation measured on the uniform
        mesh where larger, with 7–30× fewer triangles. A tolerance under the uniform mesh's
        deviation meshes the part on voxels up to half as large first. The part is then meshed whole
        (not copied cell by cell, nor in tiles)
    output: Output mesh, in the format its extension names: .stl (binary, ASCII with --ascii) or
        .3mf, streamed to the file as it is made; .obj, .off or .ply (binary, ASCII with --ascii),
        written once the part is whole; .vdb, the part's level set at its voxels (OpenVDB, a grid
        named sdf) (default: lattice.stl)
    ascii: Write ASCII STL (or ASCII PLY) instead of binary
    report: Write a JSON report (settings, densities, mesh counts, checks, timings)
    verify: How the part is verified: full (closed, manifold, outward and no self-intersection,
        exact, on the whole written part), fast (no self-intersection search), none, or cgal (CGAL's
        own checks, an independent second opinion, several times slower) (default: full) [full,
        fast, none, cgal]
    no_self_intersection_check: The same as --verify fast
    no_instancing: Mesh the whole part at once instead of copying its periodic cells from a meshed
        3×3×3-cell template (slower, same solid; the whole part is then verified)
    memory: Memory budget while meshing, e.g. 2G or 512M: a part whose grid would not fit is meshed
        in tiles sized from it and streamed to the file (default 4G)
    tile: Mesh in tiles of this many voxels a side (a multiple of 8, at least 16), whatever the
        part's size; the tiled part is the same solid as the untiled one
    keep_fragments: Keep the pieces the box cuts loose from the lattice (by default they are
        removed, so that the part is one piece; the summary and report count them either way)
    save_part: Save the settings that define this part (all but where its files go) to a TOML part
        file, once the part is made
    part: Make the part a part file describes (options given here override the file's)
    """
    ...

def fgm(
    *,
    points: Optional[Value] = None,
    two_d: bool = False,
    mesh: Optional[Value] = None,
    voxel: Optional[Value] = None,
    tolerance: Optional[Value] = None,
    sign: Optional[Value] = None,
    feature: Optional[Union[Value, List[Value]]] = None,
    weights: Optional[Value] = None,
    materials: Optional[Value] = None,
    law: Optional[Union[Value, List[Value]]] = None,
    dmax: Optional[Value] = None,
    palette: Optional[Value] = None,
    output: Optional[Value] = None,
    svg: Optional[Value] = None,
    vdb: Optional[Value] = None,
    png_stack: Optional[Value] = None,
    dpi: Optional[Value] = None,
    layer: Optional[Value] = None,
    preview: Optional[Value] = None,
    preview_z: Optional[Value] = None,
    verify: Optional[Value] = None,
    report: Optional[Value] = None,
    save_part: Optional[Value] = None,
    part: Optional[Value] = None,
    strict: bool = False,
    progress: Progress = None,
    threads: Optional[int] = None,
) -> Mesh:
    """
    Functionally graded material from distance fields: a scanned point cloud (or a mesh) to a signed
        distance grid, material fractions graded by the distance to features, and .vdb grids, a
        coloured mesh and voxel-print PNG stacks.

    points: The part as a scanned point cloud: .xyz, .txt, .csv, .asc, .pts or .ply
    2d: The points are a closed contour in a plane (x y per line): a signed distance image
    mesh: The part as a closed mesh (.stl, .obj, .off, .ply, .3mf)
    voxel: Voxel edge, mm (default: the part's longest side / 128)
    tolerance: Simplify the part's mesh within this distance of its surface, mm (of the input mesh
        with --mesh; of the surface meshed from a scan's distance field): large triangles where it
        is flat, the volume kept, the deviation measured and reported. Default: the uniform mesh,
        two triangles per voxel the surface crosses
    sign: How a scan's inside is told from its outside away from the points (default: winding)
        [winding, scan]
    feature: A feature the composition is graded from: point:X,Y,Z, curve:FILE.csv (a polyline),
        surface:FILE.stl, or skin (the part's surface); repeat for several (default: skin)
    weights: One weight per feature: the distance is their weighted mean (default: the nearest)
    materials: The materials' names, comma-separated (they name the .vdb grids) (default: A,B)
    law: A material's law, in the materials' order (the last material takes the rest): linear,
        power:P, step:FROM:TO or table:FILE.csv; repeat per material (default: linear)
    dmax: The distance at which a power law reaches 1, mm (default: the largest in the part)
    palette: Colours per material, #RRGGBB comma-separated (meshes' vertex colours, PNG stacks)
    output: The part's mesh: .ply (vertex colours), .3mf (composite materials per vertex), .stl,
        .obj or .off, or its level set alone, .vdb [default: fgm.ply]; with --2d, the signed
        distance image, .csv [default: fgm.csv]
    svg: With --2d: the outline (the zero iso-line) as SVG
    vdb: A .vdb with grids sdf, distance and one per material
    png_stack: A folder of voxel-print PNG layers (replaced whole)
    dpi: Resolution of the PNG layers, dots per inch: X or XxY (default: 600x300)
    layer: Layer thickness of the PNG stack, mm (default: 0.027)
    preview: A picture: a horizontal section coloured by composition, with a legend
    preview_z: The preview's section height, mm (default: the part's mid-height)
    verify: How the part's mesh is verified: full, fast, none or cgal (default: full) [full, fast,
        none, cgal]
    report: Write a JSON report
    save_part: Save the settings that define this part (all but where its files go) to a TOML part
        file, once the part is made
    part: Make the part a part file describes (options given here override the file's)
    """
    ...

def interpret(
    input: Union[str, os.PathLike, np.ndarray, Density], *,
    element_size: Optional[Value] = None,
    cutoff: Optional[Value] = None,
    refine: Optional[Value] = None,
    min_feature: Optional[Value] = None,
    filter_radius: Optional[Value] = None,
    max_iterations: Optional[Value] = None,
    thickness: Optional[Value] = None,
    tolerance: Optional[Value] = None,
    output: Optional[Value] = None,
    ascii: bool = False,
    iges: Optional[Value] = None,
    dxf: Optional[Value] = None,
    uniform_too: bool = False,
    report: Optional[Value] = None,
    images: Optional[Value] = None,
    boundary: Optional[Value] = None,
    cleaned: Optional[Value] = None,
    smooth: Optional[Value] = None,
    smooth_filter: Optional[Value] = None,
    verify: Optional[Value] = None,
    no_self_intersection_check: bool = False,
    strict: bool = False,
    progress: Progress = None,
    threads: Optional[int] = None,
) -> Mesh:
    """
    Density field to printable STL and parametric CAD (IGES, DXF): feature-preserving cleanup and
        adaptive B-spline fitting (Liu et al., Engineering 2018).

    element_size: Element edge length, mm (default: 1)
    cutoff: ρcutoff: threshold density of step 1.1 (default: 0.5)
    refine: nc: pixels per element edge (default 8 in 2D, 2 in 3D)
    min_feature: l_limit: the printer's minimum feature size, mm (default: 2)
    filter_radius: Density filter radius, in elements (default: 1)
    max_iterations: Bound on the repair loop's passes (default: 30)
    thickness: Extrusion of a 2D field, mm (default: one element)
    tolerance: 2D: the largest deviation of the CAD curves from the boundary, mm (default: half a
        refined pixel). 3D: simplify the mesh within this distance of the density's iso-surface (of
        the smoothed surface with --smooth): large triangles where it is flat, the volume kept, the
        deviation measured and reported (default: the uniform mesh, two triangles per voxel the
        surface crosses)
    output: Output, in the format its extension names: a mesh (.stl, .obj, .off, .ply, .3mf) or the
        part's level set (.vdb, OpenVDB, a grid named sdf) (default: part.stl)
    ascii: Write ASCII STL (or ASCII PLY)
    iges: IGES file of the adaptive B-spline curves (2D)
    dxf: DXF file of the adaptive B-spline curves (2D)
    uniform_too: Also write the uniform fits, as FILE-uniform.igs next to --iges
    report: JSON report
    images: PNG images of the stages: PREFIX-raw.png, -thresholded, -skeleton, -final
    boundary: Boundary points of the 2D result (CSV: loop, x, y in mm), the points the curves fit
    cleaned: Cleaned solid on the refined grid (.npy of 0/1, the input's layout)
    smooth: 3D: passes of OpenVDB's level-set smoothing before meshing (0: none) (default: 0)
    smooth_filter: 3D: the smoothing flow (default: gaussian) [gaussian, mean-curvature, laplacian,
        mean]
    verify: How the 3D part is verified: full, fast (no self-intersection search), none, or cgal
        (CGAL's own checks) (default: full) [full, fast, none, cgal]
    no_self_intersection_check: The same as --verify fast
    """
    ...

def topopt(
    *,
    problem: Optional[Value] = None,
    nelx: Optional[Value] = None,
    nely: Optional[Value] = None,
    nelz: Optional[Value] = None,
    volfrac: Optional[Value] = None,
    penal: Optional[Value] = None,
    rmin: Optional[Value] = None,
    filter: Optional[Value] = None,
    max_iterations: Optional[Value] = None,
    element_size: Optional[Value] = None,
    output: Optional[Value] = None,
    stiffness: Optional[Value] = None,
    log: Optional[Value] = None,
    report: Optional[Value] = None,
    strict: bool = False,
    progress: Progress = None,
    threads: Optional[int] = None,
) -> Density:
    """
    SIMP topology optimisation (88-line code in 2D, top3d in 3D): densities to .npy.

    problem: Built-in problem (mbb, cantilever, lbeam, heat, cantilever3d) or a .toml problem file
        (default: mbb)
    nelx: Elements along x
    nely: Elements along y
    nelz: Elements along z (3D problems)
    volfrac: Volume fraction (default: the problem's own, 0.5 for mbb, 0.3 otherwise)
    penal: SIMP penalty (default: 3)
    rmin: Filter radius, in elements (default: 1.5)
    filter: Filter the sensitivities (88-line ft = 1) or the densities (ft = 2; top3d's choice).
        Default: sensitivity in 2D, density in 3D [sensitivity, density]
    max_iterations: Stop after this many iterations even if the change is still above 0.01 (default:
        1000)
    element_size: Element size in mm, recorded in the report for `latvox interpret`
    output: Output densities (.npy) (default: densities.npy)
    stiffness: The design's SIMP stiffness relative to the solid (Emin + ρᵖ(1 − Emin)) at the
        elements' nodes, in the part's coordinates (shape (nelx+1, nely+1, nelz+1), y up, the box
        nelx·h × nely·h × nelz·h mm): what `tpms`, `strut` and `fill --stiffness-field` read, to
        print the design as a lattice graded by stiffness
    log: Per-iteration log (CSV: iteration, compliance, volume, change)
    report: JSON report: settings, compliance per iteration, iterations, convergence, time
    """
    ...

def homogenize(
    *,
    type: Optional[Value] = None,
    structure: Optional[Value] = None,
    side: Optional[Value] = None,
    cell: Optional[Value] = None,
    density: Optional[Value] = None,
    densities: Optional[Value] = None,
    level: Optional[Value] = None,
    radius: Optional[Value] = None,
    cell_size: Optional[Value] = None,
    voxels: Optional[Value] = None,
    voxelization: Optional[Value] = None,
    young: Optional[Value] = None,
    poisson: Optional[Value] = None,
    lame: Optional[Value] = None,
    plot: Optional[Value] = None,
    report: Optional[Value] = None,
    strict: bool = False,
    progress: Progress = None,
    threads: Optional[int] = None,
) -> Dict[str, Any]:
    """
    The effective elasticity tensor of a lattice's unit cell (numerical homogenisation).

    type: TPMS surface: p, gyroid (g), d, iwp, s, frd, neovius (n), lidinoid (l), split-p (a gyroid
        when neither --type nor --cell is given)
    structure: Solid side of the TPMS: net (F ≤ t) or sheet (|F| ≤ t) (default: net)
    side: Which labyrinth of a net is solid: first (F ≤ t) or other (−F ≤ t) (default: first)
        [first, other]
    cell: Strut cell: a built-in name (sc, bcc, bccz, fcc, fccz, octet, kelvin, diamond, rhombic) or
        a cell file (.json); struts are capsules (sharp joints)
    density: Relative density, in (0, 1], met on the voxels (0.2 when neither --level nor --radius
        is given)
    densities: Densities to tabulate the moduli over, and fit Gibson and Ashby's law E/Es = C·ρⁿ
        (and G) to: A:B:K (K densities from A to B) or a list D1,D2,…
    level: The TPMS level t instead of a density
    radius: The strut radius in mm (times each node's factor) instead of a density
    cell_size: The cell's size in mm: A or AX,AY,AZ (default: 1)
    voxels: Voxels along each axis of the cell (default: 40)
    voxelization: How a voxel weighs: the share of it the solid fills, or 1 where its centre is
        solid (default: fraction) [fraction, centres]
    young: The solid's Young's modulus (the tensor comes in its units; 1: relative to the solid)
        (default: 1)
    poisson: The solid's Poisson's ratio (default: 0.3)
    lame: The solid's Lamé constants λ,μ instead of --young and --poisson
    plot: A picture of the directional Young's modulus (the surface E(d)·d: a sphere for an
        isotropic cell) from the iso view, the front and the top (PNG)
    report: JSON report: the settings, the tensor, its inverse, the constants and the solver's work
    """
    ...

def check(
    mesh: MeshLike, *,
    report: Optional[Value] = None,
    weld_tolerance: Optional[Value] = None,
    no_self_intersection: bool = False,
    beam_voxel: Optional[Value] = None,
    strict: bool = False,
    progress: Progress = None,
    threads: Optional[int] = None,
) -> Dict[str, Any]:
    """
    Check a mesh file: every defect counted (holes, non-manifold, winding, normals, degenerate and
        duplicate facets, T-junctions, self-intersections), per shell too.

    report: Also write the JSON result to this file
    weld_tolerance: Merge vertices closer than this (mm) when reading; exact matches are always
        merged (default: 0)
    no_self_intersection: Skip the self-intersection search (the costliest check)
    beam_voxel: Voxel (mm) on which the beam lattices of a 3MF file are meshed into solids [default:
        a sixth of the thinnest beam's radius, coarser where the part would pass 2·10⁷ active
        voxels, down to four voxels across the thinnest beam]
    """
    ...

def repair(
    mesh: MeshLike, *,
    output: Optional[Value] = None,
    ascii: bool = False,
    report: Optional[Value] = None,
    weld_tolerance: Optional[Value] = None,
    no_self_intersection: bool = False,
    beam_voxel: Optional[Value] = None,
    stitch_tolerance: Optional[Value] = None,
    no_fill: bool = False,
    no_fair: bool = False,
    drop_open_shells: bool = False,
    remesh: Optional[Value] = None,
    solid: bool = False,
    tolerance: Optional[Value] = None,
    strict: bool = False,
    progress: Progress = None,
    threads: Optional[int] = None,
) -> Mesh:
    """
    Repair a mesh file and report every change by kind and count.

    output: Output mesh; the format follows the extension
    ascii: ASCII STL or ASCII PLY output (binary by default)
    report: Also write the JSON result to this file
    weld_tolerance: Merge vertices closer than this (mm) when reading; exact matches are always
        merged (default: 0)
    no_self_intersection: Skip the self-intersection search (the costliest check)
    beam_voxel: Voxel (mm) on which the beam lattices of a 3MF file are meshed into solids [default:
        a sixth of the thinnest beam's radius, coarser where the part would pass 2·10⁷ active
        voxels, down to four voxels across the thinnest beam]
    stitch_tolerance: Merge border vertices closer than this (mm) [default: 10⁻⁶ of the part's
        diagonal]
    no_fill: Leave holes open
    no_fair: Fill curved holes without fairing (triangulate and refine only)
    drop_open_shells: Drop shells that are still open after repair (they are reported either way)
    remesh: Rebuild the part through an OpenVDB level set with this voxel size (mm), or `auto`
    solid: End in one valid closed solid: drop open shells, join overlapping or crossing ones
    tolerance: Simplify what a remesh makes (--remesh, or --solid where it remeshes) within this
        distance of the input's surface, mm: fewer triangles where the part is flat, the same valid
        solid
    """
    ...

def slice(
    mesh: MeshLike, *,
    output: Optional[Value] = None,
    layer: Optional[Value] = None,
    first_layer: Optional[Value] = None,
    adaptive: Optional[Value] = None,
    c: Optional[Value] = None,
    cusp: Optional[Value] = None,
    min_layer: Optional[Value] = None,
    max_layer: Optional[Value] = None,
    direction: Optional[Value] = None,
    binary: bool = False,
    pixel: Optional[Value] = None,
    sample: Optional[Value] = None,
    format: Optional[Value] = None,
    csv: Optional[Value] = None,
    plot: Optional[Value] = None,
    repair: bool = False,
    self_intersections: bool = False,
    weld_tolerance: Optional[Value] = None,
    shard: Optional[Value] = None,
    report: Optional[Value] = None,
    strict: bool = False,
    progress: Progress = None,
    threads: Optional[int] = None,
) -> List[Layer]:
    """
    Slice a mesh file, or a part file without meshing it, into layers for printing: CLI (Common
        Layer Interface), SVG, PNG masks, SL1; uniform or adaptive layers, any build direction.

    output: Output: FILE.cli, FILE.svg, FILE.sl1, or a folder (DIR/) of PNG or SVG layers
    layer: Layer thickness, mm (uniform layers) (default: 0.05)
    first_layer: First layer's thickness, mm (uniform layers; default: --layer)
    adaptive: Adaptive layers instead of uniform ones [area, cusp]
    c: Largest relative change of area between layers (--adaptive area) (default: 0.1)
    cusp: Largest cusp height, mm (--adaptive cusp) (default: 0.01)
    min_layer: Thinnest adaptive layer, mm (default: 0.025)
    max_layer: Thickest adaptive layer, mm (default: 0.2)
    direction: Build direction (default: 0,0,1)
    binary: Binary CLI rather than ASCII (.cli output)
    pixel: Pixel size of PNG masks, mm (folder output) (default: 0.05)
    sample: Sample spacing on each layer for a part file, mm (default: a quarter of the voxel the
        part is meshed at, or a 192nd of a cell where that is finer; no coarser than --pixel for
        masks)
    format: What a folder output holds (default: png) [png, svg]
    csv: Per-layer table: z, thickness, area, perimeter, loops, holes
    plot: Plot of layer thickness and area against height (PNG)
    repair: Repair the mesh in memory when it is not a closed, outward solid
    self_intersections: Also search for self-intersecting facets (loops cross where facets do)
    weld_tolerance: Merge vertices closer than this (mm) when reading (default: 0)
    shard: Slice only this share of the layers, K of N (a folder output; also read from a Slurm
        array task's environment)
    report: Also write the JSON report to this file
    """
    ...

def render(
    part: MeshLike, width: int = 800, height: int = 600, *,
    output: Optional[Value] = None,
    view: Optional[Value] = None,
    azimuth: Optional[Value] = None,
    elevation: Optional[Value] = None,
    distance: Optional[Value] = None,
    section: Optional[Value] = None,
    turntable: Optional[Value] = None,
    animate: bool = False,
    depth: Optional[Value] = None,
    strict: bool = False,
    progress: Progress = None,
    threads: Optional[int] = None,
) -> np.ndarray:
    """
    Render a picture of a part file, sphere-traced from its implicit solid without meshing it, or of
        a mesh file, ray cast.

    output: The picture, PNG (default: view.png)
    view: Where the camera looks from (default: iso) [iso, front, back, left, right, top, bottom]
    azimuth: Azimuth in degrees (overrides the view's): 0 front, 90 right, 180 back, −90 left
    elevation: Elevation in degrees above the xy plane (overrides the view's), −90 to 90
    distance: Distance from the eye to the part's centre, mm (default: the part fills the picture)
    section: Cut away the part beyond a plane to show its inside: AXIS=MM removes what lies above
        (x=, y= or z=), AXIS<MM keeps what lies below and AXIS>MM what lies above
    turntable: N views around the part (the azimuth stepped by 360°/N), side by side in one picture
    animate: With --turntable: an animated PNG (APNG) of the views, a tenth of a second each,
        instead of a strip
    depth: Also write the depth per pixel (mm from the eye, inf where the ray missed) as .npy (the
        views side by side, with --turntable)
    """
    ...
