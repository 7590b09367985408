//! A part read from a file: its triangles as read, and the beam lattices of a 3MF file (Beam
//! Lattice extension) made solids through the pipeline.
//!
//! Each lattice's beams and balls are a [`BeamField`] (exact distances to the frustums, caps
//! and spheres); its clipping mesh and the triangles of the object that holds it are OpenVDB
//! distance grids of their meshes; the lattice's solid is
//!
//! ```text
//! S = min( max(B, ±C), M )      (+C: clipped inside the mesh, −C: outside; M: its triangles)
//! ```
//!
//! — the unification the extension specifies — and the part's lattices are meshed together as
//! one solid (OpenVDB's volume-to-mesh, vertices snapped onto the beams' exact surface), on
//! voxels of a sixth of the thinnest beam's radius unless given, coarser only as far as the
//! memory bound asks. The triangles of the file's other objects are kept as read, beside it.

use crate::error::{Error, Result};
use crate::field::beams::{Beam, BeamField};
use crate::field::{intersection_clearance, union_clearance, Aabb, Field, Vec3};
use crate::geom::Mesh;
use crate::grid::{distance_clearance, Grid, GridSpec, SPARE_VOXELS};
use crate::io::threemf::{BeamLattice, Clipping};
use crate::io::{BeamsMeshed, Loaded, ReadOptions};
use crate::mesh::pipeline::{mesh_keyed, part_spec, Solid, HALF_WIDTH};
use std::path::Path;

/// The default voxel: this fraction of the thinnest radius (twelve voxels across the thinnest
/// beam). The mesh's vertices lie on the beams and its facets are chords of them: a beam's
/// volume comes out short by at most about (voxel/radius)²/6, half a percent here.
pub const VOXELS_PER_RADIUS: f64 = 6.0;

/// The most active voxels the automatic voxel allows (about 8 bytes each in the grid, and a
/// triangle per three in the mesh).
pub const MAX_ACTIVE_VOXELS: f64 = 2.0e7;

/// Reads the part in `path`: [`crate::io::read`], and its beam lattices meshed into its mesh
/// (on voxels of `opts.beam_voxel` mm when given).
pub fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded> {
    let mut loaded = crate::io::read(path, opts)?;
    if loaded.lattices.is_empty() {
        return Ok(loaded);
    }
    let lattices = std::mem::take(&mut loaded.lattices);
    let (mesh, meshed) = mesh_lattices(&lattices, opts.beam_voxel).map_err(|e| e.in_file(path))?;
    loaded.mesh = join(std::mem::take(&mut loaded.mesh), &mesh);
    loaded.beams = Some(meshed);
    Ok(loaded)
}

/// `a` and `b` in one mesh (vertices of `b` after those of `a`).
fn join(mut a: Mesh, b: &Mesh) -> Mesh {
    let base = a.vertex_count() as u32;
    a.positions.extend_from_slice(&b.positions);
    a.indices.extend(b.indices.iter().map(|i| i + base));
    a
}

/// The thinnest radius of the lattices' beams and balls, mm.
fn thinnest(lattices: &[BeamLattice]) -> f64 {
    lattices
        .iter()
        .flat_map(|l| {
            l.beams
                .iter()
                .flat_map(|b| b.radii)
                .chain(l.balls.iter().map(|b| b.1))
        })
        .fold(f64::INFINITY, f64::min)
}

/// The area of the lattices' beams' sides, balls and meshes, mm² (about the surface's: the
/// caps mostly lie inside joints, and joints overlap).
fn area(lattices: &[BeamLattice]) -> f64 {
    use std::f64::consts::PI;
    lattices
        .iter()
        .map(|l| {
            let p = |i: u32| l.vertices[i as usize];
            let beams: f64 = l
                .beams
                .iter()
                .map(|b| {
                    let [a, c] = b.ends.map(p);
                    let len = (0..3).map(|k| (a[k] - c[k]).powi(2)).sum::<f64>().sqrt();
                    let [r1, r2] = b.radii;
                    let slant = (len * len + (r1 - r2).powi(2)).sqrt();
                    PI * (r1 + r2) * slant
                })
                .sum();
            let balls: f64 = l.balls.iter().map(|b| 4.0 * PI * b.1 * b.1).sum();
            beams + balls + l.mesh.area()
        })
        .sum()
}

/// The voxel for `lattices`: `given`, or a sixth of the thinnest radius, coarsened so that
/// the narrow band (six voxels across the surface) holds at most [`MAX_ACTIVE_VOXELS`] — but
/// never beyond half the thinnest radius (four voxels across the thinnest beam), below which
/// beams would break apart: such a part takes the memory it needs.
pub fn lattice_voxel(lattices: &[BeamLattice], given: Option<f64>) -> Result<(f64, f64)> {
    let r = thinnest(lattices);
    if let Some(v) = given {
        if !(v.is_finite() && v > 0.0) {
            return Err(Error::invalid("the beam voxel must be a length > 0 mm"));
        }
        return Ok((v, r));
    }
    if !r.is_finite() {
        // Only the objects' meshes: their size decides.
        let b = lattices
            .iter()
            .filter_map(|l| l.mesh.bounds())
            .fold(None::<Aabb>, |u, b| {
                Some(u.map_or(b, |u| union_box(&u, &b)))
            });
        let e = b.map_or(1.0, |b| b.size().into_iter().fold(0.0, f64::max));
        return Ok((e / 200.0, r));
    }
    let bound = (2.0 * HALF_WIDTH * area(lattices) / MAX_ACTIVE_VOXELS).sqrt();
    Ok(((r / VOXELS_PER_RADIUS).max(bound).min(r / 2.0), r))
}

fn union_box(a: &Aabb, b: &Aabb) -> Aabb {
    Aabb {
        min: [0, 1, 2].map(|k| a.min[k].min(b.min[k])),
        max: [0, 1, 2].map(|k| a.max[k].max(b.max[k])),
    }
}

fn intersect_box(a: &Aabb, b: &Aabb) -> Aabb {
    Aabb {
        min: [0, 1, 2].map(|k| a.min[k].max(b.min[k])),
        max: [0, 1, 2].map(|k| a.max[k].min(b.max[k]).max(a.min[k].max(b.min[k]))),
    }
}

/// Meshes `lattices` as one solid on voxels of `voxel` mm (automatic when `None`).
pub fn mesh_lattices(lattices: &[BeamLattice], voxel: Option<f64>) -> Result<(Mesh, BeamsMeshed)> {
    let (voxel, thinnest) = lattice_voxel(lattices, voxel)?;
    let solid = LatticeSolid::new(lattices, voxel)?;
    let mesh = match solid.bounds {
        Some(b) if b.volume() > 0.0 => {
            let (keyed, _) = mesh_keyed(&solid, part_spec(&solid, voxel), None, 0.0, None)?;
            keyed.into_mesh()
        }
        _ => Mesh::default(),
    };
    if mesh.triangle_count() == 0 {
        return Err(Error::parse(format!(
            "3MF: the beam lattice leaves no solid on voxels of {voxel} mm (clipped away, or thinner than the voxels)"
        )));
    }
    let triangles = mesh.triangle_count() as u64;
    Ok((
        mesh,
        BeamsMeshed {
            lattices: lattices.len() as u64,
            beams: lattices.iter().map(|l| l.beams.len() as u64).sum(),
            balls: lattices.iter().map(|l| l.balls.len() as u64).sum(),
            short_beams_ignored: lattices.iter().map(|l| l.short_beams).sum(),
            thinnest_radius: thinnest,
            voxel,
            triangles,
        },
    ))
}

/// A clipping mesh ready to sample: a box exactly, any other mesh as a distance grid.
enum Clip {
    Box(Aabb),
    Grid(Grid),
}

impl Clip {
    fn value_and_clearance(&self, p: Vec3, voxel: f64) -> (f64, f64) {
        match self {
            Clip::Box(b) => {
                let v = b.value(p);
                (v, v.abs())
            }
            Clip::Grid(g) => {
                let v = g.value_at(p);
                (v, distance_clearance(v, voxel))
            }
        }
    }
}

/// The box `m` bounds when it is one: eight corners, twelve facets, its volume the box's
/// (latvox's own beam files clip by a box).
fn as_box(m: &Mesh) -> Option<Aabb> {
    let b = m.bounds()?;
    let on = |x: f32, k: usize| x as f64 == b.min[k] || x as f64 == b.max[k];
    let corners = m
        .positions
        .chunks_exact(3)
        .all(|p| (0..3).all(|k| on(p[k], k)));
    (corners
        && m.vertex_count() == 8
        && m.triangle_count() == 12
        && (m.volume().abs() - b.volume()).abs() <= 1e-9 * b.volume())
    .then_some(b)
}

/// One lattice ready to sample.
struct Prepared {
    beams: BeamField,
    clip: Option<(Clipping, Clip)>,
    mesh: Option<Grid>,
}

/// The lattices of a part as one solid.
struct LatticeSolid {
    lattices: Vec<Prepared>,
    /// The solid's box (grown by two voxels), `None` when it is empty.
    bounds: Option<Aabb>,
    voxel: f64,
}

impl LatticeSolid {
    fn new(lattices: &[BeamLattice], voxel: f64) -> Result<LatticeSolid> {
        let spare = HALF_WIDTH + SPARE_VOXELS;
        // The beams' field is exact across the band and a voxel beyond it.
        let reach = (HALF_WIDTH + 1.0) * voxel;
        let mut prepared = Vec::with_capacity(lattices.len());
        let mut bounds: Option<Aabb> = None;
        // Whether every lattice is clipped inside a box: the boxes' union bounds the solid
        // exactly, and its faces are the mesher's clip planes (vertices snapped onto them).
        let mut boxed = true;
        for l in lattices {
            let beams: Vec<Beam> = l
                .beams
                .iter()
                .map(|b| Beam {
                    ends: b.ends.map(|i| l.vertices[i as usize]),
                    radii: b.radii,
                    caps: b.caps,
                })
                .collect();
            let balls: Vec<(Vec3, f64)> = l
                .balls
                .iter()
                .map(|&(v, r)| (l.vertices[v as usize], r))
                .collect();
            let field = BeamField::new(&beams, &balls, reach);
            // Two voxels clear of the beams: a box's faces clip the solid only where the
            // clipping box cuts it, never where a beam just touches its bounds.
            let mut b = (!field.is_empty()).then(|| field.bounds().grown(2.0 * voxel));
            let clip = match &l.clip {
                None => None,
                Some((side, m)) => {
                    if let (Clipping::Inside, Some(c)) = (side, m.bounds()) {
                        b = b.map(|b| intersect_box(&b, &c));
                    }
                    Some((
                        *side,
                        match as_box(m) {
                            Some(b) => Clip::Box(b),
                            None => Clip::Grid(Grid::distance_to_mesh(m, voxel, spare, spare)?),
                        },
                    ))
                }
            };
            boxed &= l.mesh.triangle_count() == 0
                && matches!(l.clip, Some((Clipping::Inside, _)))
                && matches!(clip, Some((_, Clip::Box(_))));
            let mesh = match l.mesh.bounds() {
                None => None,
                Some(m) => {
                    b = Some(b.map_or(m, |b| union_box(&b, &m)));
                    Some(Grid::distance_to_mesh(&l.mesh, voxel, spare, spare)?)
                }
            };
            if let Some(b) = b {
                bounds = Some(bounds.map_or(b, |u| union_box(&u, &b)));
            }
            prepared.push(Prepared {
                beams: field,
                clip,
                mesh,
            });
        }
        Ok(LatticeSolid {
            lattices: prepared,
            bounds: bounds.map(|b| if boxed { b } else { b.grown(2.0 * voxel) }),
            voxel,
        })
    }
}

impl Solid for LatticeSolid {
    fn field(&self, _: &GridSpec) -> Box<dyn Field + '_> {
        Box::new(LatticeField { solid: self })
    }
    fn bounds(&self) -> Aabb {
        self.bounds.unwrap_or(Aabb {
            min: [0.0; 3],
            max: [0.0; 3],
        })
    }
    fn with_bounds(&self, _: Aabb) -> Self {
        unreachable!("a lattice read from a file is meshed whole")
    }
    fn period(&self) -> Option<Vec3> {
        None
    }
}

struct LatticeField<'a> {
    solid: &'a LatticeSolid,
}

impl LatticeField<'_> {
    /// Value and clearance of lattice `l` at `p`.
    fn one(&self, l: &Prepared, p: Vec3) -> (f64, f64) {
        let h = self.solid.voxel;
        let v = l.beams.value(p);
        let mut out = (v, l.beams.clearance(p));
        if let Some((side, clip)) = &l.clip {
            let (c, cc) = clip.value_and_clearance(p, h);
            let c = if *side == Clipping::Inside { c } else { -c };
            out = (out.0.max(c), intersection_clearance(out.0, out.1, c, cc));
        }
        if let Some(g) = &l.mesh {
            let m = g.value_at(p);
            let cm = distance_clearance(m, h);
            out = (out.0.min(m), union_clearance(out.0, out.1, m, cm));
        }
        out
    }
}

impl Field for LatticeField<'_> {
    fn value(&self, p: Vec3) -> f64 {
        self.value_and_clearance(p).0
    }
    fn clearance(&self, p: Vec3) -> f64 {
        self.value_and_clearance(p).1
    }
    fn value_and_clearance(&self, p: Vec3) -> (f64, f64) {
        let mut it = self.solid.lattices.iter().map(|l| self.one(l, p));
        let first = it.next().unwrap_or((f64::INFINITY, f64::INFINITY));
        it.fold(first, |(a, ca), (b, cb)| {
            (a.min(b), union_clearance(a, ca, b, cb))
        })
    }
    /// Vertices are snapped onto the beams' surface only where no clipping surface or grid
    /// comes near (but the solid's own box, whose planes the mesher snaps onto): a grid's
    /// surface (a clipping mesh, the object's triangles) is known only as well as OpenVDB's
    /// vertices already lie on it, and where a box cuts a beam two surfaces meet at an edge.
    /// The value and its gradient: where the beams of one lattice give the value, the
    /// gradient of their nearest piece (cheap); elsewhere (a clip or a mesh gives it) by
    /// central differences of the whole.
    fn implicit_with_gradient(&self, p: Vec3) -> (f64, Vec3) {
        let v = self.value(p);
        for l in &self.solid.lattices {
            let (b, g) = l.beams.implicit_with_gradient(p);
            if b == v {
                return (v, g);
            }
        }
        (v, crate::field::numeric_gradient(|q| self.value(q), p))
    }

    fn smooth_near(&self, p: Vec3, reach: f64) -> bool {
        let far = reach + self.solid.voxel;
        self.solid.lattices.iter().all(|l| {
            let clear = match &l.clip {
                None => true,
                Some((_, Clip::Box(b))) if Some(*b) == self.solid.bounds => true,
                Some((_, Clip::Box(b))) => b.value(p).abs() > far,
                Some((_, Clip::Grid(g))) => g.value_at(p).abs() > far,
            };
            clear && l.mesh.as_ref().is_none_or(|g| g.value_at(p).abs() > far)
        })
    }
}
