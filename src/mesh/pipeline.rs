//! The pipeline: any solid clipped by its box → a verified mesh streamed to a sink, at the
//! level that gives it its target volume fraction.
//!
//! A capability describes its geometry as a [`Family`] of [`Solid`]s indexed by a level (the TPMS
//! level `t`, a strut radius, …) that thickens the solid as it grows. The pipeline then:
//!
//! 1. **routes** the part ([`Route`]): copied cell by cell from a meshed template when the solid
//!    is periodic and the cells span whole OpenVDB leaves ([`crate::mesh::instance`]), meshed in tiles
//!    when its grid would not fit the memory budget ([`crate::mesh::tile`]), or meshed whole;
//! 2. **finds the level on the part itself** ([`solve`]): the part is meshed (or, for large
//!    periodic parts, a template of its cells is — [`Template::part_volume`] gives the whole
//!    part's volume from it), its loose fragments removed, its volume fraction measured, and
//!    the level corrected until the fraction is within [`AIM`] of the target: a part that is
//!    not a whole number of cells, or meshed on coarse voxels, gets the level that is right
//!    for *it*, not for the periodic cell;
//! 3. **writes** it: the whole mesh after CGAL's checks, the copies of the template (checked
//!    by CGAL) or the tiles (each checked as it is written), dropping the fragments.
//!
//! When no level gives the target within [`PROMISE`] on these voxels (a lattice whose members
//! are thinner than the voxels falls apart below some level and jumps in volume above it),
//! [`solve`] says so with the closest fraction it found, and the caller raises the resolution
//! or refuses.

use crate::error::{Error, Result};
use crate::field::{Aabb, Field, Intersection, Vec3};
use crate::geom::Mesh;
use crate::grid::{Grid, GridSpec, IndexBox};
use crate::io::sink::{Measures, MeshSink, Triangle};
use crate::mesh::extract::KeyedMesh;
use crate::mesh::instance::{self, AxisPlan, Template};
use crate::mesh::pieces::{self, Fragments};
pub use crate::mesh::simplify::Simplified;
use crate::mesh::simplify::{self, SimplifyStats, Surface};
use crate::mesh::snap::SnapStats;
use crate::mesh::tile;
use crate::progress::Progress;
use crate::verify::cgal::Verification;
use crate::verify::{verify, Verify};
use std::time::Instant;

/// Default narrow-band half width, voxels.
pub const HALF_WIDTH: f64 = 3.0;

/// The density a written part must have: within this of the target.
pub const PROMISE: f64 = 0.002;

/// The level is corrected until the part's measured fraction is within this of the target.
pub const AIM: f64 = 0.001;

/// Meshings of the part (or its template) the level search may take.
pub const MAX_MESHINGS: u32 = 8;

/// Memory a part may use while it is meshed when no budget is given: larger parts are meshed
/// in tiles.
pub const DEFAULT_MEMORY: u64 = 4 << 30;

/// A solid clipped by its box: what the pipeline needs of a capability's geometry.
pub trait Solid: Sync {
    /// The solid's field, unclipped, set up for sampling on voxels of `spec` (a periodic solid
    /// samples by index modulo its cell where a cell is a whole number of voxels, so that cells
    /// mesh alike), its values clamped to the narrow band.
    fn field(&self, spec: &GridSpec) -> Box<dyn Field + '_>;
    /// The clipping box.
    fn bounds(&self) -> Aabb;
    /// The same solid clipped by another box (a template, a calibration cell).
    fn with_bounds(&self, bounds: Aabb) -> Self
    where
        Self: Sized;
    /// The cell size per axis, when the solid repeats with cells starting at its box's lower
    /// corner.
    fn period(&self) -> Option<Vec3>;
    /// Whether the field is exact enough to snap vertices onto (a field interpolated from
    /// samples is not: OpenVDB's vertices already lie on it as closely as it is known, and
    /// snapping onto its creases folds triangles).
    fn snaps(&self) -> bool {
        true
    }
}

/// Solids indexed by a level; the solid grows with the level.
pub trait Family: Sync {
    /// The solid at one level.
    type Solid: Solid;
    /// The solid at `level`.
    fn at(&self, level: f64) -> Self::Solid;
    /// The volume fraction of the exact (unmeshed) solid at `level`, or a model of it that
    /// increases with the level: the search steps the level through it.
    fn model_fraction(&self, level: f64) -> f64;
    /// The inverse of [`Family::model_fraction`].
    fn model_level(&self, fraction: f64) -> f64;
    /// The fraction the search aims at, of a part in `bounds` that encloses `volume` mm³: its
    /// share of the box unless the family measures its density against something else (a
    /// filled part: the lattice's share of the region it fills).
    fn fraction(&self, volume: f64, bounds: &Aabb) -> f64 {
        volume / bounds.volume()
    }
}

/// Statistics of meshing.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct MeshingStats {
    /// Voxel edge, mm.
    pub voxel_size: f64,
    /// Leaf blocks tested against the field's clearance.
    pub blocks_tested: u64,
    /// Leaf blocks sampled (those the narrow band reached).
    pub blocks_sampled: u64,
    /// Active voxels of the grids (the narrow band).
    pub active_voxels: u64,
    /// Memory of the largest grid, bytes (OpenVDB's count).
    pub grid_bytes: u64,
    /// What snapping did to the vertices.
    pub snap: SnapStats,
    /// Time spent sampling, seconds.
    pub sample_seconds: f64,
    /// Time spent in OpenVDB's meshing, seconds.
    pub mesh_seconds: f64,
    /// Time spent snapping, seconds.
    pub snap_seconds: f64,
}

impl MeshingStats {
    /// Adds another pass's counts and times (tiles of one part, meshings of a search).
    pub fn add(&mut self, o: &MeshingStats) {
        self.voxel_size = o.voxel_size;
        self.blocks_tested += o.blocks_tested;
        self.blocks_sampled += o.blocks_sampled;
        self.active_voxels += o.active_voxels;
        self.grid_bytes = self.grid_bytes.max(o.grid_bytes);
        self.snap += o.snap;
        self.sample_seconds += o.sample_seconds;
        self.mesh_seconds += o.mesh_seconds;
        self.snap_seconds += o.snap_seconds;
    }
}

/// Samples `solid` on `spec` (on the blocks covering `region` only, for a tile), meshes it with
/// OpenVDB and snaps the vertices onto the exact surface and box; with `snap_within`, only the
/// vertices there are snapped (when only part of the mesh is measured).
pub fn mesh_keyed<S: Solid + ?Sized>(
    solid: &S,
    spec: GridSpec,
    region: Option<IndexBox>,
    adaptivity: f64,
    snap_within: Option<&Aabb>,
) -> Result<(KeyedMesh, MeshingStats)> {
    let field = solid.field(&spec);
    let bounds = solid.bounds();
    let clipped = Intersection {
        a: &*field,
        b: bounds,
    };
    let t = Instant::now();
    let grid = match region {
        Some(r) => Grid::sample_box(&clipped, spec, r)?,
        None => Grid::sample(&clipped, spec)?,
    };
    let sample_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut keyed = if adaptivity == 0.0 {
        KeyedMesh::extract(&grid)?
    } else {
        KeyedMesh::from_adaptive(&grid.to_mesh(adaptivity)?, &spec)
    };
    let mesh_seconds = t.elapsed().as_secs_f64();
    let stats = MeshingStats {
        voxel_size: spec.voxel,
        blocks_tested: grid.blocks_tested,
        blocks_sampled: grid.blocks_sampled,
        active_voxels: grid.active_voxels(),
        grid_bytes: grid.memory_bytes(),
        sample_seconds,
        mesh_seconds,
        ..Default::default()
    };
    drop(grid);
    let t = Instant::now();
    let snap = if solid.snaps() {
        crate::mesh::snap::snap_within(&mut keyed, &*field, &bounds, &spec, snap_within)
    } else {
        keyed.triangulate();
        SnapStats::default()
    };
    Ok((
        keyed,
        MeshingStats {
            snap,
            snap_seconds: t.elapsed().as_secs_f64(),
            ..stats
        },
    ))
}

/// The grid a whole part is meshed on.
pub fn part_spec<S: Solid + ?Sized>(solid: &S, voxel: f64) -> GridSpec {
    GridSpec::covering(&solid.bounds(), voxel, HALF_WIDTH)
}

/// How the part is written, and what it is meshed with.
#[derive(Debug, Clone, Copy, Default)]
pub struct Options {
    /// The name `--adaptivity` had for OpenVDB's volumeToMesh adaptivity, 0 to 1, kept as a
    /// tolerance of that many voxels ([`Options::tolerance_at`]): OpenVDB's adaptive meshes
    /// could cross themselves.
    pub adaptivity: f64,
    /// Simplify the mesh within this distance of the exact surface (see
    /// [`crate::mesh::simplify`]); the part is then meshed whole and its density measured on
    /// the simplified mesh.
    pub tolerance: Option<Tolerance>,
    /// How the written part is verified.
    pub verify: Verify,
    /// Copy a periodic part's cells from a meshed template where possible.
    pub instancing: bool,
    /// Mesh in tiles of this many samples a side (a multiple of 8), whatever the part's size.
    pub tile: Option<i64>,
    /// Memory budget, bytes ([`DEFAULT_MEMORY`] when not given).
    pub memory: Option<u64>,
    /// Keep the fragments the box cuts loose (they are removed by default).
    pub keep_fragments: bool,
}

impl Options {
    /// The tolerance the mesh is simplified within on voxels of `voxel` mm: the one asked, or
    /// `adaptivity` voxels.
    pub fn tolerance_at(&self, voxel: f64) -> Option<Tolerance> {
        self.tolerance
            .or((self.adaptivity > 0.0).then_some(Tolerance::Mm(self.adaptivity * voxel)))
    }
}

/// How far a simplified mesh may stray from the exact surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tolerance {
    /// At most this distance, mm.
    Mm(f64),
    /// The default mesh's deviation: half a voxel, or the deviation the uniform mesh on the
    /// part's voxels measures where that is larger (where the box cuts the lattice at a graze,
    /// where struts meet).
    Auto,
}

impl Tolerance {
    /// `auto` ([`Tolerance::Auto`]) or a positive length in mm.
    pub fn parse(s: &str) -> std::result::Result<Tolerance, String> {
        if s.trim() == "auto" {
            return Ok(Tolerance::Auto);
        }
        match s.trim().parse::<f64>() {
            Ok(v) if v > 0.0 && v.is_finite() => Ok(Tolerance::Mm(v)),
            _ => Err(format!("{s} must be a positive length in mm, or auto")),
        }
    }
}

/// How a part is meshed and written.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Route {
    /// Copied cell by cell from a meshed template.
    Instanced([AxisPlan; 3]),
    /// Meshed tile by tile, tiles of this many samples a side; the level is found on a
    /// measuring template of its cells when there is one.
    Tiled(i64, Option<[AxisPlan; 3]>),
    /// Meshed at once; the level is found on a measuring template of its cells when there is
    /// one, on the whole part otherwise.
    Whole(Option<[AxisPlan; 3]>),
}

impl Route {
    /// Chooses the route for `solid` on voxels of size `voxel`.
    pub fn choose<S: Solid>(solid: &S, voxel: f64, o: &Options) -> Route {
        let bounds = solid.bounds();
        let plan = |f: fn(Vec3, Vec3, f64) -> Option<[AxisPlan; 3]>| {
            solid.period().and_then(|c| f(bounds.size(), c, voxel))
        };
        let simplified = o.tolerance_at(voxel).is_some();
        if o.instancing && o.tile.is_none() && !simplified {
            if let Some(p) = plan(instance::plan) {
                return Route::Instanced(p);
            }
        }
        let budget = o.memory.unwrap_or(DEFAULT_MEMORY);
        // Memory grows with the triangles as much as with the voxels: the surface's density
        // is probed on the part's grid before anything is meshed, unless the part would fit
        // at any density.
        let probed = std::cell::OnceCell::new();
        let density = || {
            *probed.get_or_init(|| {
                let spec = part_spec(solid, voxel);
                let field = solid.field(&spec);
                let clipped = Intersection {
                    a: &*field,
                    b: bounds,
                };
                tile::triangle_density(&clipped, &spec)
            })
        };
        let fits = |b: &Aabb| {
            let voxels = GridSpec::covering(b, voxel, HALF_WIDTH)
                .padded_region()
                .voxels();
            let within = |d: f64| tile::meshing_bytes(voxels, d) + tile::RESERVED_BYTES <= budget;
            within(tile::MAX_TRIANGLE_DENSITY) || within(density())
        };
        // A measuring template is worth meshing when it is small beside the part (each level
        // tried meshes it, and the part is meshed once more at the level found) and when it
        // fits in memory.
        let measuring = plan(instance::measuring_plan).filter(|p| {
            let (part, template): (i64, i64) = (
                p.iter().map(|a| a.n).product(),
                p.iter().map(|a| a.m).product(),
            );
            let cell = solid.period().expect("a plan needs a period");
            part >= 4 * template && fits(&instance::template_bounds(&bounds, cell, p))
        });
        if simplified {
            // Simplified whole (copies and tiles would need their seams held).
            return Route::Whole(measuring);
        }
        match o.tile {
            Some(edge) => Route::Tiled(edge, measuring),
            None if !fits(&bounds) => {
                Route::Tiled(tile::tile_edge_for_budget(budget, density()), measuring)
            }
            None => Route::Whole(measuring),
        }
    }
}

/// A part meshed at one level, ready to be written.
pub enum Made {
    /// The whole part's mesh (fragments removed unless kept).
    Whole(KeyedMesh),
    /// The part's template, to be copied.
    Template(Template),
    /// Nothing held: the part is meshed again, tile by tile, as it is written; the measuring
    /// template (if any) says which vertices belong to fragments.
    Tiles(Option<Template>),
    /// Nothing held but the part's pieces, found across its tiles: it is meshed again, on the
    /// same tiles, as it is written, and its fragments dropped.
    TilePieces(tile::TiledPieces),
}

/// A part meshed (or measured) at one level.
pub struct Measured {
    /// The level meshed.
    pub level: f64,
    /// Volume fraction of what will be written.
    pub fraction: f64,
    /// Volume of what will be written, mm³.
    pub volume: f64,
    /// What was meshed: the whole part, its template, or nothing held (tiles).
    pub made: Made,
    /// Fragments the box cuts loose.
    pub fragments: Fragments,
    /// Meshing statistics of this level.
    pub meshing: MeshingStats,
    /// Edges of one facet only in what was meshed (the whole part or its template; 0 where
    /// nothing is held): holes that voxels too coarse for the members left.
    pub open_edges: u64,
    /// The fragments removed, as shells, when the whole part was meshed (see [`loose`]).
    loose: pieces::Loose,
}

/// Meshes or measures the solid at `level` on its route.
pub fn measure<F: Family>(
    family: &F,
    level: f64,
    voxel: f64,
    route: Route,
    o: &Options,
) -> Result<Measured> {
    measure_observed(family, level, voxel, route, o, &mut VolumeSink)
}

/// [`measure`], the triangles of a part measured tile by tile without a template (nothing
/// held) passed to `observer` as they are meshed (fragments included).
pub fn measure_observed<F: Family>(
    family: &F,
    level: f64,
    voxel: f64,
    route: Route,
    o: &Options,
    observer: &mut dyn MeshSink,
) -> Result<Measured> {
    let solid = family.at(level);
    let template = |plan| Template::build(&solid, voxel, plan, o.keep_fragments);
    let mut loose = pieces::Loose::default();
    let (made, volume, fragments, meshing) = match route {
        Route::Instanced(plan) | Route::Whole(Some(plan)) | Route::Tiled(_, Some(plan)) => {
            let (t, stats) = template(plan)?;
            let (v, f) = (t.part_volume(), t.part_fragments());
            let made = match route {
                Route::Instanced(_) => Made::Template(t),
                Route::Tiled(..) => Made::Tiles(Some(t)),
                // The whole part is meshed once the level is known.
                Route::Whole(_) => Made::Tiles(Some(t)),
            };
            (made, v, f, stats)
        }
        Route::Whole(None) => {
            let (mut mesh, stats) = mesh_keyed(&solid, part_spec(&solid, voxel), None, 0.0, None)?;
            let f = if o.keep_fragments {
                pieces::Shells::of(&mesh).fragments(false)
            } else {
                let (f, shells) = pieces::remove_fragments(&mut mesh);
                loose = pieces::Loose::of(shells);
                f
            };
            let v = keyed_volume(&mesh);
            (Made::Whole(mesh), v, f, stats)
        }
        Route::Tiled(edge, None) => {
            // No template: the part's volume and pieces are found tile by tile, nothing written.
            let (v, stats, found) = tiled_volume(&solid, voxel, edge, true, observer)?;
            let found = found.expect("pieces were asked for");
            let mut f = found.fragments;
            f.removed = !o.keep_fragments;
            let v = if f.removed { v - f.volume } else { v };
            (Made::TilePieces(found), v, f, stats)
        }
    };
    let open_edges = match &made {
        Made::Whole(mesh) => mesh.open_edges(),
        Made::Template(t) | Made::Tiles(Some(t)) => t.mesh.open_edges(),
        _ => 0,
    };
    Ok(Measured {
        level,
        fraction: family.fraction(volume, &solid.bounds()),
        volume,
        made,
        fragments,
        meshing,
        open_edges,
        loose,
    })
}

/// The fragments removed from the part measured in `m` (at its level, on `voxel`), as shells a
/// point can be tested against: the whole part's, the template's (standing for every copy),
/// or — for a part measured tile by tile, which held no mesh — each fragment meshed again
/// within its bounds, two voxels round, its closed shell taken from that small mesh.
pub fn loose<F: Family>(family: &F, m: &Measured, voxel: f64) -> Result<pieces::Loose> {
    Ok(match &m.made {
        Made::Template(t) | Made::Tiles(Some(t)) => t.loose().clone(),
        Made::TilePieces(found) if !found.loose.is_empty() => {
            let solid = family.at(m.level);
            let spec = part_spec(&solid, voxel);
            let mut triangles = Vec::new();
            for (_, b) in &found.loose {
                let index = |x: f64, a: usize| ((x - spec.origin[a]) / voxel).floor() as i64;
                let region = IndexBox {
                    lo: [0, 1, 2].map(|a| index(b.min[a], a) - 2),
                    hi: [0, 1, 2].map(|a| index(b.max[a], a) + 3),
                };
                let (mesh, _) = mesh_keyed(&solid, spec, Some(region), 0.0, None)?;
                let shells = pieces::Shells::of(&mesh);
                let within = b.grown(0.5 * voxel);
                let inside = |s: &Aabb| {
                    (0..3).all(|a| s.min[a] >= within.min[a] && s.max[a] <= within.max[a])
                };
                let mut keep = shells.bounds.iter().map(|s| !inside(s)).collect::<Vec<_>>();
                // The fragment's shells are the small mesh's only ones within its bounds.
                let shells = pieces::Shells {
                    kept: std::mem::take(&mut keep),
                    ..shells
                };
                triangles.extend(pieces::loose_triangles(&mesh, &shells));
            }
            pieces::Loose::of(triangles)
        }
        _ => m.loose.clone(),
    })
}

/// The level at which the exact solid (not its mesh) encloses what the part measured in `m`
/// encloses: the level an implicit route (slices straight from the part, no mesh) takes, so
/// that it holds the mesh's volume. A mesh whose vertices lie on a curved surface cuts its
/// chords, and voxels round the sharp edges where the box cuts the lattice: on thin members the
/// mesh encloses about a percent less than the exact solid at its level, at 32 voxels a cell.
/// The exact solid's volume is integrated ([`crate::field::volume::volume_extrapolated`], on
/// steps of `step` mm and twice that, extrapolated: no coarser than [`implicit_step`]) over
/// what was meshed — the whole part, or each template cell times the cells it stands for — less
/// the fragments removed; the level moves by the difference over the solid's growth per level
/// (the search's last secant, or the family's model), and once more by the secant through the
/// two exact volumes. The integration holds nothing but its own stack, whatever the part's
/// size.
pub fn implicit_level<F: Family>(
    family: &F,
    m: &Measured,
    tried: &[(f64, f64)],
    voxel: f64,
    step: f64,
) -> f64 {
    let bounds = family.at(m.level).bounds();
    let boxes: Vec<(Aabb, u64)> = match &m.made {
        Made::Template(t) | Made::Tiles(Some(t)) => t.cells_with_counts(&bounds),
        _ => vec![(bounds, 1)],
    };
    let removed = if m.fragments.removed {
        m.fragments.volume
    } else {
        0.0
    };
    let exact = |level: f64| -> f64 {
        let solid = family.at(level);
        let spec = part_spec(&solid, voxel);
        let field = solid.field(&spec);
        boxes
            .iter()
            .map(|(b, count)| {
                let clipped = Intersection { a: &*field, b: *b };
                *count as f64 * crate::field::volume::volume_extrapolated(&clipped, b, step)
            })
            .sum::<f64>()
            - removed
    };
    // Fraction per volume, and the solid's growth in volume per level: the search's last
    // secant where it took two meshings, the model's slope otherwise.
    let per_volume = family.fraction(1.0, &bounds) - family.fraction(0.0, &bounds);
    let secant = tried
        .windows(2)
        .last()
        .map(|w| (w[1].1 - w[0].1) / (w[1].0 - w[0].0))
        .filter(|s| s.is_finite() && *s > 0.0);
    let slope = secant.unwrap_or_else(|| {
        let f = family.model_fraction(m.level);
        let (lo, hi) = ((f - 0.01).max(1e-3), (f + 0.01).min(1.0 - 1e-3));
        (hi - lo) / (family.model_level(hi) - family.model_level(lo))
    }) / per_volume;
    if !(slope.is_finite() && slope > 0.0) {
        return m.level;
    }
    let e0 = exact(m.level) - m.volume;
    let t1 = m.level - e0 / slope;
    let e1 = exact(t1) - m.volume;
    let t2 = t1 - e1 * (t1 - m.level) / (e1 - e0);
    if t2.is_finite() && e1.abs() > 1e-9 * m.volume.abs() {
        t2
    } else {
        t1
    }
}

/// The step [`implicit_level`] integrates on for a part meshed on `voxel` in cells whose shortest
/// side is `cell`: the voxel, or a 48th of the cell where that is finer (coarse voxels leave
/// the members a few steps across, where a step's plane is no longer the surface).
pub fn implicit_step(voxel: f64, cell: f64) -> f64 {
    voxel.min(cell / 48.0)
}

/// The volume of `solid` meshed on `route` (whole, or tile by tile without keeping the tiles),
/// fragments included, mm³.
pub fn solid_volume<S: Solid>(solid: &S, voxel: f64, route: Route) -> Result<(f64, MeshingStats)> {
    match route {
        Route::Tiled(edge, _) => {
            tiled_volume(solid, voxel, edge, false, &mut VolumeSink).map(|(v, stats, _)| (v, stats))
        }
        _ => {
            let (mesh, stats) = mesh_keyed(solid, part_spec(solid, voxel), None, 0.0, None)?;
            Ok((keyed_volume(&mesh), stats))
        }
    }
}

/// Enclosed volume of a keyed mesh as it is written (single-precision corners), mm³.
pub fn keyed_volume(mesh: &KeyedMesh) -> f64 {
    use crate::geom::signed_volume;
    let tris: Vec<[u32; 3]> = mesh.triangles().collect();
    crate::geom::ordered_sum(tris.len(), |i| {
        let [a, b, c] = tris[i].map(|v| mesh.positions[v as usize].map(|x| x as f32 as f64));
        signed_volume(a, b, c)
    })
}

/// The volume of the part meshed tile by tile (fragments included) without writing it, and,
/// when asked, its pieces.
fn tiled_volume<S: Solid>(
    solid: &S,
    voxel: f64,
    edge: i64,
    find_pieces: bool,
    sink: &mut dyn MeshSink,
) -> Result<(f64, MeshingStats, Option<tile::TiledPieces>)> {
    let spec = part_spec(solid, voxel);
    let stats = std::sync::Mutex::new(MeshingStats::default());
    let mesh_tile = |r: IndexBox| {
        let (m, s) = mesh_keyed(solid, spec, Some(r), 0.0, None)?;
        stats
            .lock()
            .expect("no panic while holding the lock")
            .add(&s);
        Ok(m)
    };
    let out = tile::mesh_tiled(
        spec.padded_region(),
        edge,
        &mesh_tile,
        Verify::Fast,
        if find_pieces {
            tile::Pieces::Find
        } else {
            tile::Pieces::Keep
        },
        &Progress::hidden(),
        sink,
    )?;
    Ok((
        out.measures.volume,
        stats.into_inner().expect("no panic while holding the lock"),
        out.pieces,
    ))
}

/// A sink that keeps nothing (tiles are measured as they pass).
#[derive(Default)]
pub struct VolumeSink;

impl MeshSink for VolumeSink {
    fn begin(&mut self, _: Option<u64>) -> Result<()> {
        Ok(())
    }
    fn triangles(&mut self, _: &[Triangle]) -> Result<()> {
        Ok(())
    }
    fn finish(&mut self) -> Result<()> {
        Ok(())
    }
}

/// The level search's outcome.
pub struct Solved {
    /// The part at the level found (the closest one when the target was missed).
    pub best: Measured,
    /// Levels meshed and the fraction each gave, in order.
    pub tried: Vec<(f64, f64)>,
    /// Whether the fraction is within [`PROMISE`] of the target.
    pub met: bool,
    /// Meshing statistics of every meshing the search took.
    pub meshing: MeshingStats,
}

/// A part found at one resolution: its voxel, route, the part at its level and the search.
pub struct Found {
    /// Voxel edge, mm.
    pub voxel: f64,
    /// How it is meshed.
    pub route: Route,
    /// The part at the level found (or given).
    pub best: Measured,
    /// Levels meshed and the fraction each gave, in order.
    pub tried: Vec<(f64, f64)>,
    /// Meshing statistics of the search.
    pub meshing: MeshingStats,
}

/// The part on voxels of `voxel` on `route`: at the level that gives `target` (the closest
/// fraction found when none does, as `Err`), or measured at `level` when there is no target —
/// one attempt of a resolution search ([`crate::mesh::resolution::search`]).
pub fn find<F: Family>(
    family: &F,
    target: Option<f64>,
    level: f64,
    voxel: f64,
    route: Route,
    o: &Options,
) -> Result<std::result::Result<Found, f64>> {
    Ok(match target {
        Some(d) => {
            let solved = solve(family, d, level, voxel, route, o)?;
            if !solved.met {
                return Ok(Err(solved.best.fraction));
            }
            Ok(Found {
                voxel,
                route,
                best: solved.best,
                tried: solved.tried,
                meshing: solved.meshing,
            })
        }
        None => {
            let best = measure(family, level, voxel, route, o)?;
            Ok(Found {
                voxel,
                route,
                tried: vec![(level, best.fraction)],
                meshing: best.meshing,
                best,
            })
        }
    })
}

/// Finds the level at which the part's measured volume fraction is `target`, starting from
/// `start`: each step reads the next level off the family's model at the target less the
/// difference between measured and modelled fraction (the meshing's and the box's effect, which
/// change slowly with the level); once the target is bracketed, regula falsi (Illinois) on the
/// measured fractions. Stops within [`AIM`], or after [`MAX_MESHINGS`], or when the bracket
/// closes on a jump (the solid falls apart on these voxels between two levels).
pub fn solve<F: Family>(
    family: &F,
    target: f64,
    start: f64,
    voxel: f64,
    route: Route,
    o: &Options,
) -> Result<Solved> {
    let mut tried = Vec::new();
    let mut meshing = MeshingStats::default();
    let mut best: Option<Measured> = None;
    // Bracket: (level, fraction − target as weighted by Illinois, fraction) below and above.
    let mut lo: Option<(f64, f64, f64)> = None;
    let mut hi: Option<(f64, f64, f64)> = None;
    let mut side = 0i8;
    let mut t = start;
    for _ in 0..MAX_MESHINGS {
        let m = measure(family, t, voxel, route, o)?;
        meshing.add(&m.meshing);
        let err = m.fraction - target;
        tried.push((t, m.fraction));
        if err < 0.0 {
            if side == -1 {
                if let Some(h) = hi.as_mut() {
                    h.1 *= 0.5;
                }
            }
            side = -1;
            lo = Some((t, err, m.fraction));
        } else {
            if side == 1 {
                if let Some(l) = lo.as_mut() {
                    l.1 *= 0.5;
                }
            }
            side = 1;
            hi = Some((t, err, m.fraction));
        }
        if best
            .as_ref()
            .is_none_or(|b| err.abs() < (b.fraction - target).abs())
        {
            best = Some(m);
        }
        let best_err = best
            .as_ref()
            .map_or(f64::INFINITY, |b| (b.fraction - target).abs());
        if best_err <= AIM {
            break;
        }
        t = match (lo, hi) {
            (Some((a, fa, pa)), Some((b, fb, pb))) => {
                // How much the exact solid changes between the two levels, against how much
                // the measured part does: far more means a jump (the part falls apart on these
                // voxels below it), which regula falsi would creep up on; bisect instead, and
                // stop once the jump is pinned or the closer side keeps the promise.
                let gap = (family.model_fraction(b) - family.model_fraction(a)).abs();
                let jump = (pb - pa).abs() > 4.0 * gap;
                if gap < 1e-4 || (jump && best_err <= PROMISE) {
                    break;
                }
                if jump {
                    0.5 * (a + b)
                } else {
                    (a * fb - b * fa) / (fb - fa)
                }
            }
            _ => {
                let bias = (err + target) - family.model_fraction(t);
                let next = family.model_level((target - bias).clamp(1e-6, 1.0 - 1e-6));
                if next == t {
                    // The model is flat here: step by the error in the model's own terms.
                    t + err.signum() * -1e-3 * (1.0 + t.abs())
                } else {
                    next
                }
            }
        };
    }
    let best = best.expect("at least one meshing");
    // A part with holes does not meet its density: the voxels are too coarse for its members.
    let met = (best.fraction - target).abs() <= PROMISE && best.open_edges == 0;
    Ok(Solved {
        best,
        tried,
        met,
        meshing,
    })
}

/// Timings and checks of writing a part.
pub struct Written {
    /// CGAL's checks (on the template when copied; counted per tile when tiled).
    pub checks: Verification,
    /// Meshing statistics.
    pub meshing: MeshingStats,
    /// Measures of the triangles written.
    pub measures: Measures,
    /// Vertices of the written part.
    pub vertices: u64,
    /// Fragments found, and whether they were dropped.
    pub fragments: Fragments,
    /// Set when the part was copied from a template.
    pub instancing: Option<Instancing>,
    /// Set when the part was meshed in tiles.
    pub tiling: Option<Tiling>,
    /// Set when the mesh was simplified within a tolerance.
    pub simplified: Option<Simplified>,
    /// Time of CGAL's checks, seconds.
    pub verify_seconds: f64,
    /// Time of writing, seconds.
    pub write_seconds: f64,
}

/// How the part was meshed when it was copied from a template (see [`crate::mesh::instance`]).
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Instancing {
    /// Cells of the part per axis that the template stands for (1 along axes not copied).
    pub part_cells: [i64; 3],
    /// Cells of the template per axis.
    pub template_cells: [i64; 3],
    /// Triangles of the template.
    pub template_triangles: u64,
    /// The checks ran on the template, which holds every kind of cell the part has; the part is
    /// written as exact copies of its cells.
    pub verified: &'static str,
}

/// How the part was meshed when it was meshed in tiles (see [`crate::mesh::tile`]).
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Tiling {
    /// Tiles meshed.
    pub tiles: u64,
    /// Tile edge, samples.
    pub tile_samples: i64,
    /// Samples meshed around each tile and not kept.
    pub margin_samples: i64,
    /// What was checked, and by whom.
    pub verified: &'static str,
}

/// Writes the part measured in `m` to `sink`, checking it on the way.
pub fn write<F: Family>(
    family: &F,
    m: Measured,
    voxel: f64,
    route: Route,
    o: &Options,
    progress: &Progress,
    sink: &mut dyn MeshSink,
) -> Result<Written> {
    let solid = family.at(m.level);
    match (route, m.made) {
        (Route::Instanced(plan), Made::Template(t)) => {
            write_instanced(t, plan, m.meshing, m.fragments, o, progress, sink)
        }
        (Route::Whole(_), Made::Whole(mesh)) => {
            let f = Some(m.fragments);
            write_part(&solid, mesh, voxel, m.meshing, f, o, progress, sink)
        }
        (Route::Whole(_), Made::Tiles(_)) => {
            // Found on a measuring template: mesh the part at the level found.
            let (mesh, meshing) = {
                let _p = progress.stage("sampling and meshing");
                mesh_keyed(&solid, part_spec(&solid, voxel), None, 0.0, None)?
            };
            write_part(&solid, mesh, voxel, meshing, None, o, progress, sink)
        }
        (Route::Tiled(edge, _), Made::Tiles(template)) => write_tiled(
            &solid,
            voxel,
            edge,
            template.as_ref(),
            None,
            m.fragments,
            o,
            progress,
            sink,
        ),
        (Route::Tiled(edge, _), Made::TilePieces(found)) => write_tiled(
            &solid,
            voxel,
            edge,
            None,
            Some(&found),
            m.fragments,
            o,
            progress,
            sink,
        ),
        _ => Err(Error::invalid("a part was measured on another route")),
    }
}

/// Writes the whole part's `mesh`, simplified when a tolerance is asked; its fragments are
/// `found` already (and removed unless kept), or found and removed here.
#[allow(clippy::too_many_arguments)]
fn write_part<S: Solid>(
    solid: &S,
    mut mesh: KeyedMesh,
    voxel: f64,
    meshing: MeshingStats,
    found: Option<Fragments>,
    o: &Options,
    progress: &Progress,
    sink: &mut dyn MeshSink,
) -> Result<Written> {
    let fragments = match found {
        Some(f) => f,
        None if o.keep_fragments => pieces::Shells::of(&mesh).fragments(false),
        None => pieces::remove_fragments(&mut mesh).0,
    };
    let Some(tolerance) = o.tolerance_at(voxel) else {
        return write_whole(mesh.into_mesh(), meshing, fragments, o, progress, sink);
    };
    let (mesh, simplified) = {
        let _p = progress.stage("simplifying");
        let t = Instant::now();
        let (mesh, mut simplified) =
            simplify_part(solid, mesh.into_mesh(), voxel, tolerance, o.keep_fragments)?;
        simplified.stats.seconds = t.elapsed().as_secs_f64();
        (mesh, simplified)
    };
    let mut w = write_whole(mesh, meshing, fragments, o, progress, sink)?;
    w.simplified = Some(simplified);
    Ok(w)
}

/// Simplifies the part's uniform `mesh` (made on `voxel`) within `tolerance` of `solid`'s exact
/// surface ([`Tolerance::Auto`]: half a voxel or the uniform mesh's deviation, measured here). Where the
/// uniform mesh itself strays further than a tolerance in mm (it rounds the sharp edges where the
/// box cuts the lattice, or struts meet, by about half a voxel), the part is meshed again on
/// voxels that much finer first (at most half as large). The result's volume is restored to the uniform
/// mesh's, which the level search measured; its deviation is measured, and where it exceeds
/// the tolerance (between the samples each collapse checks) the part is simplified again at a
/// smaller one.
fn simplify_part<S: Solid>(
    solid: &S,
    mesh: Mesh,
    voxel: f64,
    tolerance: Tolerance,
    keep_fragments: bool,
) -> Result<(Mesh, Simplified)> {
    let volume = mesh.volume();
    let requested_triangles = mesh.triangle_count() as u64;
    let field_on = |used: f64| solid.field(&part_spec(solid, used));
    let clip = solid.bounds();
    let uniform = {
        let field = field_on(voxel);
        let surface = Surface {
            field: &*field,
            clip,
        };
        simplify::deviation(&mesh, surface, 0.25 * voxel)
    };
    let auto = tolerance == Tolerance::Auto;
    // The voxels to simplify on, in turn, and the tries on each: a tolerance in mm that the
    // uniform mesh nearly reaches is met on voxels that much finer (at most half the voxel: four
    // times the triangles to simplify); auto likewise where the uniform mesh's deviation sets it
    // (the volume's offset pushes the worst of its valleys out), else on the part's voxels and,
    // where no try keeps within it there, on voxels a little finer.
    let tolerance = match tolerance {
        Tolerance::Mm(t) => t,
        Tolerance::Auto => uniform.max(0.5 * voxel),
    };
    let on = |scale: f64| (scale * voxel, simplify::TRIES);
    let voxels = match (uniform > 0.9 * tolerance, auto) {
        (true, false) => vec![on((0.8 * tolerance / uniform).max(0.5))],
        (true, true) => vec![on(0.8)],
        (false, false) => vec![on(1.0)],
        (false, true) => vec![on(1.0), on(0.8)],
    };
    let report = |stats: SimplifyStats, deviation: f64, used: f64| Simplified {
        stats: SimplifyStats { tolerance, ..stats },
        deviation,
        voxel: used,
        uniform_deviation: uniform,
        uniform_triangles: requested_triangles,
        auto,
    };
    let mut finer: Option<(Mesh, f64)> = None;
    for (used, tries) in voxels {
        if used != voxel {
            let (mut keyed, _) = mesh_keyed(solid, part_spec(solid, used), None, 0.0, None)?;
            if !keep_fragments {
                pieces::remove_fragments(&mut keyed);
            }
            finer = Some((keyed.into_mesh(), used));
        }
        let base = finer.as_ref().map_or(&mesh, |f| &f.0);
        let field = field_on(used);
        let surface = Surface {
            field: &*field,
            clip,
        };
        // Where the uniform mesh strays further than asked even so, those triangles stay as
        // they are and the rest is held to the tolerance (auto: the tolerance is that deviation
        // on the part's voxels, a bound on finer ones too).
        let bound = if auto || used == voxel {
            tolerance.max(uniform)
        } else {
            tolerance.max(simplify::deviation(base, surface, 0.25 * used))
        };
        let w = simplify::within(base, surface, used, (tolerance, bound), Some(volume), tries);
        if w.kept {
            return Ok((w.mesh, report(w.stats, w.deviation, used)));
        }
    }
    // Not simplified within the tolerance: the uniform mesh, within its own deviation as it was
    // (auto), or the finest one made, its volume restored.
    let gave_up = |n: usize, offset: f64| SimplifyStats {
        triangles_before: n as u64,
        triangles_after: n as u64,
        offset,
        gave_up: true,
        ..Default::default()
    };
    let (mut base, used) = match finer {
        Some(f) if !auto => f,
        _ => {
            let n = mesh.triangle_count();
            return Ok((mesh, report(gave_up(n, 0.0), uniform, voxel)));
        }
    };
    let field = field_on(used);
    let surface = Surface {
        field: &*field,
        clip,
    };
    let still = vec![false; base.vertex_count()];
    let offset = simplify::restore_volume(&mut base, surface, used, volume, &still);
    let deviation = simplify::deviation(&base, surface, 0.25 * used);
    let stats = gave_up(base.triangle_count(), offset);
    Ok((base, report(stats, deviation, used)))
}

fn write_instanced(
    template: Template,
    plan: [AxisPlan; 3],
    meshing: MeshingStats,
    fragments: Fragments,
    o: &Options,
    progress: &Progress,
    sink: &mut dyn MeshSink,
) -> Result<Written> {
    // The template is verified while the part is written: the two share the cores.
    let template_mesh = template.mesh.to_mesh();
    let (checks, verify_seconds, measures, write_seconds) = {
        let _p = progress.stage("writing the part and verifying its template");
        std::thread::scope(|scope| {
            let checker = scope.spawn(|| {
                let t = Instant::now();
                let r = match o.verify {
                    // CGAL's parallel search would take the writer's core.
                    Verify::Cgal => crate::verify::cgal::verify_on(&template_mesh, true, false),
                    v => verify(&template_mesh, v, &Progress::hidden()),
                };
                (r, t.elapsed().as_secs_f64())
            });
            let t = Instant::now();
            let measures = template.expand(sink);
            let write_seconds = t.elapsed().as_secs_f64();
            let (checks, verify_seconds) = checker.join().expect("the CGAL check does not panic");
            (checks, verify_seconds, measures, write_seconds)
        })
    };
    Ok(Written {
        checks: checks?,
        meshing,
        measures: measures?,
        vertices: template.vertex_count(),
        fragments,
        instancing: Some(Instancing {
            part_cells: plan.map(|a| a.n),
            template_cells: plan.map(|a| a.m),
            template_triangles: template.mesh.triangle_count() as u64,
            verified: "template",
        }),
        tiling: None,
        simplified: None,
        verify_seconds,
        write_seconds,
    })
}

#[allow(clippy::too_many_arguments)]
fn write_tiled<S: Solid>(
    solid: &S,
    voxel: f64,
    edge: i64,
    template: Option<&Template>,
    found: Option<&tile::TiledPieces>,
    fragments: Fragments,
    o: &Options,
    progress: &Progress,
    sink: &mut dyn MeshSink,
) -> Result<Written> {
    let spec = part_spec(solid, voxel);
    let pieces = match found {
        Some(p) if !o.keep_fragments => tile::Pieces::Drop(p),
        _ => tile::Pieces::Keep,
    };
    let stats = std::sync::Mutex::new(MeshingStats::default());
    let mesh_tile = |r: IndexBox| {
        let (mut m, s) = mesh_keyed(solid, spec, Some(r), 0.0, None)?;
        stats
            .lock()
            .expect("no panic while holding the lock")
            .add(&s);
        if let Some(t) = template.filter(|_| !o.keep_fragments) {
            let keep: Vec<bool> = m.keys.iter().map(|k| !t.is_fragment(k)).collect();
            if keep.iter().any(|&k| !k) {
                pieces::retain(&mut m, &keep);
            }
        }
        Ok(m)
    };
    let t = Instant::now();
    let out = {
        let _p = progress.stage("meshing and writing the part tile by tile");
        tile::mesh_tiled(
            spec.padded_region(),
            edge,
            &mesh_tile,
            o.verify,
            pieces,
            progress,
            sink,
        )?
    };
    // Edges are counted whatever is asked; with `--verify none` nothing is judged on them.
    let closed = out.bad_edges == 0 || o.verify == Verify::None;
    let m = out.measures;
    Ok(Written {
        checks: Verification {
            checked_by: o.verify.by(),
            manifold: closed,
            closed,
            outward: closed && m.volume > 0.0,
            self_intersection_checked: out.self_intersection_checked,
            self_intersecting: out.self_intersecting,
            volume: closed.then_some(m.volume),
            area: m.area,
            faces: m.triangles,
            vertices: out.vertices,
            border_edges: out.bad_edges,
            components: 0,
            not_checked: None,
        },
        meshing: stats.into_inner().expect("no panic while holding the lock"),
        measures: m,
        vertices: out.vertices,
        fragments,
        instancing: None,
        tiling: Some(Tiling {
            tiles: out.tiles,
            tile_samples: edge,
            margin_samples: tile::MARGIN,
            verified: match o.verify {
                Verify::Full => "every tile as written, seams included: edges and self-intersections by latvox",
                Verify::Cgal => "every tile as written, seams included: edges by latvox, self-intersections by CGAL",
                Verify::Fast => "every tile as written: edges by latvox; self-intersections not searched",
                Verify::None => "not verified",
            },
        }),
        simplified: None,
        verify_seconds: 0.0,
        write_seconds: t.elapsed().as_secs_f64(),
    })
}

fn write_whole(
    mesh: Mesh,
    meshing: MeshingStats,
    fragments: Fragments,
    o: &Options,
    progress: &Progress,
    sink: &mut dyn MeshSink,
) -> Result<Written> {
    // The part is verified while it is written. The search runs on threads of its own, as many
    // as rayon's: in the shared pool the writer's short batches would queue behind its long
    // tasks (writing took longer than verifying); beside it, the system shares the cores.
    let (checks, verify_seconds, measures, write_seconds) = std::thread::scope(|scope| {
        let checker = scope.spawn(|| {
            let t = Instant::now();
            let r = match rayon::ThreadPoolBuilder::new()
                .num_threads(rayon::current_num_threads())
                .build()
            {
                Ok(pool) => pool.install(|| verify(&mesh, o.verify, progress)),
                Err(_) => verify(&mesh, o.verify, progress),
            };
            (r, t.elapsed().as_secs_f64())
        });
        let t = Instant::now();
        let measures = write_mesh(&mesh, sink);
        let write_seconds = t.elapsed().as_secs_f64();
        let (checks, verify_seconds) = checker.join().expect("the verification does not panic");
        (checks, verify_seconds, measures, write_seconds)
    });
    Ok(Written {
        checks: checks?,
        meshing,
        measures: measures?,
        vertices: mesh.vertex_count() as u64,
        fragments,
        instancing: None,
        tiling: None,
        simplified: None,
        verify_seconds,
        write_seconds,
    })
}

/// Streams an in-memory mesh into `sink` in batches, measuring it on the way.
pub fn write_mesh(mesh: &Mesh, sink: &mut dyn MeshSink) -> Result<Measures> {
    use rayon::prelude::*;
    sink.begin(Some(mesh.triangle_count() as u64))?;
    let mut measures = Measures::default();
    const BATCH: usize = 1 << 16;
    for start in (0..mesh.triangle_count()).step_by(BATCH) {
        let end = (start + BATCH).min(mesh.triangle_count());
        let tris: Vec<Triangle> = (start..end)
            .into_par_iter()
            .map(|t| {
                let i = &mesh.indices[3 * t..3 * t + 3];
                [i[0], i[1], i[2]].map(|v| {
                    let p = &mesh.positions[3 * v as usize..3 * v as usize + 3];
                    [p[0], p[1], p[2]]
                })
            })
            .collect();
        measures = measures.merged(&Measures::of(&tris));
        sink.triangles(&tris)?;
    }
    sink.finish()?;
    Ok(measures)
}
