//! Pictures of parts without meshing them: rays cast from a camera at a [`trace::Scene`] — an
//! implicit solid sphere-traced straight from its field ([`trace::Implicit`]), or a triangle
//! mesh through a BVH ([`trace::Triangles`], to compare a meshed part with its implicit) —
//! shaded from the surface normal with a key and a fill light and, for implicit solids, ambient
//! occlusion read from the field. Pixels are traced in parallel (rayon) over 16 × 16 tiles;
//! memory is the image and the scene's own (a unit cell's struts, a mesh's BVH), whatever the
//! number of cells.

pub mod camera;
pub mod trace;
pub mod view;

use crate::error::{Error, Result};
use crate::field::{Aabb, Field, Vec3};
use crate::grid::GridSpec;
use crate::lattice::strut::StrutFamily;
use crate::mesh::pieces::Loose;
use crate::mesh::pipeline::{self, Family, Found, Options, Solid};
use camera::{dot, normalized, Camera};
use rayon::prelude::*;
use std::path::Path;
use trace::{Scene, Tolerance};

/// What an implicit model of a part is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fidelity {
    /// Pictures and the editor: the solid at the level its mesh is written at — the surface the
    /// mesh approximates.
    Look,
    /// Slices, which are printed: the level moved so that the exact solid encloses what the
    /// mesh encloses ([`crate::mesh::pipeline::implicit_level`]; a few micrometres on a lattice
    /// at 32 voxels a cell), so that the layers hold the part's density.
    Volume,
}

/// Memory the level search of an implicit model may use (its part is meshed in tiles beyond
/// it): the implicit routes exist to show and slice parts too large to mesh whole, and the
/// level found does not depend on the tiles.
pub const MODEL_MEMORY: u64 = 512 << 20;

/// `options` with the memory budget capped at [`MODEL_MEMORY`], for the search a model's level
/// is found by (in tiles beyond it).
pub fn model_options(options: &Options) -> Options {
    Options {
        memory: Some(
            options
                .memory
                .unwrap_or(pipeline::DEFAULT_MEMORY)
                .min(MODEL_MEMORY),
        ),
        ..*options
    }
}

/// A part as an implicit solid, at the level (a TPMS's `t`, a strut radius, a foam's radius or
/// wall thickness) its mesh is written
/// at — found by the same search, on the same route and voxels — with the fragments its mesh
/// drops: what rendering and slicing trace instead of a mesh. Its field is unclipped; the box
/// clips it.
pub struct Model {
    /// The lattice (its field unclipped; [`Solid::bounds`] is the clipping box).
    pub lattice: Lattice,
    /// The TPMS level, the strut radius or a foam's member size (mm), the solid is built at.
    pub level: f64,
    /// The voxel meshing it would use, mm: the scale of its finest features.
    pub voxel: f64,
    /// The shortest cell side (a foam's spacing), mm.
    pub cell: f64,
    /// The volume fraction the part is made to, when it is made to one.
    pub target: Option<f64>,
    /// The fragments the box cuts loose, which the mesh drops.
    pub loose: Loose,
}

impl Model {
    /// A strut lattice's model, its radius found by `found` (the part's search on its mesh):
    /// the radius `given`, or the one the mesh is made to at, for slices
    /// ([`Fidelity::Volume`]) moved so that the solid encloses the mesh's volume; with the
    /// fragments the mesh drops.
    pub fn of_struts(
        family: &StrutFamily,
        found: &Found,
        given: Option<f64>,
        target: Option<f64>,
        fidelity: Fidelity,
    ) -> Result<Model> {
        let c = family.part.size;
        let cell = c[0].min(c[1]).min(c[2]);
        let step = pipeline::implicit_step(found.voxel, cell);
        Model::of(
            family,
            found,
            given,
            target,
            fidelity,
            [cell, step],
            |f, r| Lattice::Struts(f.at(r)),
        )
    }

    /// The model of any family's part, its level found by `found` (the part's search on its
    /// mesh): the level `given`, or the one the mesh is made at, for slices
    /// ([`Fidelity::Volume`]) moved so that the solid encloses the mesh's volume; with the
    /// fragments the mesh drops. `cell` is the lattice's scale (its shortest cell side, a
    /// foam's spacing), `step` what [`pipeline::implicit_level`] integrates on, and `lattice`
    /// the family's solid at a level as the renderer draws it.
    pub fn of<F: Family>(
        family: &F,
        found: &Found,
        given: Option<f64>,
        target: Option<f64>,
        fidelity: Fidelity,
        [cell, step]: [f64; 2],
        lattice: impl FnOnce(&F, f64) -> Lattice,
    ) -> Result<Model> {
        let level = match given {
            // A level given is the part's level, whatever its mesh encloses.
            Some(l) => l,
            None if fidelity == Fidelity::Look => found.best.level,
            None => pipeline::implicit_level(family, &found.best, &found.tried, found.voxel, step),
        };
        Ok(Model {
            level,
            lattice: lattice(family, level),
            voxel: found.voxel,
            cell,
            target,
            loose: pipeline::loose(family, &found.best, found.voxel)?,
        })
    }

    /// The distance up to which a strut field is exact (its value is capped there): 0.15 of a
    /// cell, so that the augmented cell holds few struts and a step in empty space still
    /// crosses a good part of a cell (the fastest of 0.1–0.4 on BCC and filled parts).
    pub fn reach(&self) -> f64 {
        0.15 * self.cell
    }

    /// The solid's field, unclipped.
    pub fn field(&self) -> Box<dyn Field + '_> {
        let spec = GridSpec::covering(
            &self.solid().bounds(),
            self.voxel,
            (self.reach() / self.voxel).max(1.0),
        );
        self.solid().field(&spec)
    }

    /// The solid.
    pub fn solid(&self) -> &(dyn Solid + Send) {
        self.lattice.solid()
    }

    /// The clipping box.
    pub fn bounds(&self) -> Aabb {
        self.solid().bounds()
    }
}

/// A lattice clipped by its box: what a part file describes and the browser editor's shader
/// draws.
#[derive(Debug, Clone)]
pub enum Lattice {
    /// A TPMS lattice.
    Tpms(crate::lattice::tpms::Lattice),
    /// A strut lattice.
    Struts(crate::lattice::strut::StrutLattice),
    /// A Voronoi foam (a periodic net is a strut lattice).
    Foam(crate::lattice::voronoi::FoamSolid),
}

impl Lattice {
    /// The lattice as a solid.
    pub fn solid(&self) -> &(dyn Solid + Send) {
        match self {
            Lattice::Tpms(l) => l,
            Lattice::Struts(l) => l,
            Lattice::Foam(f) => f,
        }
    }
}

/// A rendered image with its depth.
#[derive(Debug, Clone)]
pub struct Frame {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// RGB, row by row from the top.
    pub rgb: Vec<u8>,
    /// Distance from the eye to the surface per pixel, mm (infinite where the ray missed).
    pub depth: Vec<f32>,
}

/// Pixels traced together: a square tile's edge.
const TILE: u32 = 16;
/// The part's colour, and the colour of the faces a section cuts.
const BODY: Vec3 = [0.60, 0.66, 0.76];
const CAP: Vec3 = [0.86, 0.46, 0.34];

/// A traced pixel: where, its colour and its depth.
type Pixel = (u32, u32, [u8; 3], f32);

/// Renders `scene` through `camera`.
pub fn render(scene: &dyn Scene, camera: &Camera) -> Frame {
    let (w, h) = (camera.width, camera.height);
    let tol = Tolerance {
        absolute: 0.0,
        per_distance: 0.25 * camera.pixel_at(1.0),
    };
    let tiles_x = w.div_ceil(TILE);
    let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..tiles_x).map(move |tx| (tx, ty)))
        .collect();
    let light_key = normalized(
        [0, 1, 2].map(|a| -camera.forward[a] + 0.8 * camera.up[a] - 0.6 * camera.right[a]),
    );
    let light_fill = normalized(
        [0, 1, 2].map(|a| -camera.forward[a] - 0.2 * camera.up[a] + 0.9 * camera.right[a]),
    );
    let done: Vec<Vec<Pixel>> = tiles
        .par_iter()
        .map(|&(tx, ty)| {
            let mut out = Vec::with_capacity((TILE * TILE) as usize);
            for y in ty * TILE..((ty + 1) * TILE).min(h) {
                for x in tx * TILE..((tx + 1) * TILE).min(w) {
                    let ray = camera.ray(x as f64, y as f64);
                    let (rgb, depth) = match scene.hit(&ray, tol) {
                        Some(hit) => {
                            let p = ray.at(hit.t);
                            let n = hit.normal;
                            let open = scene.openness(p, n);
                            let key = dot(n, light_key).max(0.0);
                            let fill = dot(n, light_fill).max(0.0);
                            let base = if hit.cap { CAP } else { BODY };
                            let shade = (0.22 + 0.68 * key + 0.25 * fill) * (0.35 + 0.65 * open);
                            let c = base.map(|b| (255.0 * (b * shade).clamp(0.0, 1.0)) as u8);
                            (c, hit.t as f32)
                        }
                        None => (background(y as f64 / h as f64), f32::INFINITY),
                    };
                    out.push((x, y, rgb, depth));
                }
            }
            out
        })
        .collect();
    let mut frame = Frame {
        width: w,
        height: h,
        rgb: vec![0; (w * h * 3) as usize],
        depth: vec![f32::INFINITY; (w * h) as usize],
    };
    for (x, y, c, d) in done.into_iter().flatten() {
        let i = (y * w + x) as usize;
        frame.rgb[3 * i..3 * i + 3].copy_from_slice(&c);
        frame.depth[i] = d;
    }
    frame
}

/// A soft vertical gradient, light at the top.
fn background(v: f64) -> [u8; 3] {
    let top = [247.0, 248.0, 250.0];
    let bottom = [222.0, 226.0, 232.0];
    [0, 1, 2].map(|a| (top[a] + (bottom[a] - top[a]) * v) as u8)
}

impl Frame {
    /// Pixels where a ray met the scene.
    pub fn hits(&self) -> usize {
        self.depth.iter().filter(|d| d.is_finite()).count()
    }

    /// Frames of one height side by side, left to right.
    pub fn strip(frames: &[Frame]) -> Result<Frame> {
        let Some(first) = frames.first() else {
            return Err(Error::invalid("no frames to put side by side"));
        };
        let h = first.height;
        if frames.iter().any(|f| f.height != h) {
            return Err(Error::invalid("frames of a strip must be of one height"));
        }
        let w: u32 = frames.iter().map(|f| f.width).sum();
        let mut out = Frame {
            width: w,
            height: h,
            rgb: Vec::with_capacity((w * h * 3) as usize),
            depth: Vec::with_capacity((w * h) as usize),
        };
        for y in 0..h as usize {
            for f in frames {
                let row = y * f.width as usize;
                out.rgb
                    .extend_from_slice(&f.rgb[3 * row..3 * (row + f.width as usize)]);
                out.depth
                    .extend_from_slice(&f.depth[row..row + f.width as usize]);
            }
        }
        Ok(out)
    }

    /// Writes the image as an 8-bit RGB PNG, atomically.
    pub fn write_png(&self, path: &Path) -> Result<()> {
        crate::io::png::write_rgb(path, self.width, self.height, &self.rgb)
    }

    /// Writes the depth (mm from the eye, infinite where nothing was hit) as a float64 `.npy`
    /// of shape (height, width), atomically.
    pub fn write_depth(&self, path: &Path) -> Result<()> {
        let data: Vec<f64> = self.depth.iter().map(|&d| d as f64).collect();
        let shape = [self.height as usize, self.width as usize];
        crate::io::atomic::write_atomic(path, |w| crate::io::npy::write(w, &shape, &data))
    }
}
