//! A part filled with a lattice, as a field: the part's signed distance (OpenVDB's
//! meshToSignedDistanceField of its mesh, read trilinearly) combined with the lattice's.
//!
//! With `P` the part's distance (negative inside), `T` the skin thickness, `L` the lattice's
//! field and `K` the union of the solids kept whole, the filled part is
//!
//! ```text
//! F = min( max(P, S), K ),   S = smin(−P − T, L)   (S = L without a skin)
//! ```
//!
//! `−P − T ≤ 0` is the skin (the part less its core, the points deeper than `T`); its union
//! with the lattice, cut by the part, keeps the skin and the lattice inside the core; `smin` is
//! the smooth minimum of radius `--blend` (a sharp union at 0) that fillets the lattice into the
//! skin. The same field with no lattice (`S = −P − T`) is the skin alone, and with the part
//! full (`F = min(P, K)`) the whole part: their volumes give the region the lattice fills, so
//! the lattice's density is measured on it.
//!
//! A skin closes the lattice's void inside the part: powder or resin left in it cannot get out.
//! Drain holes (`--drain D`) are cylinders of diameter `D` through the skin, cut from every one
//! of these fields alike (`max(F, −H)`, `H` the distance to the holes), so that the regions and
//! the density are measured on the part as drilled: one at the part's lowest facet and one at
//! its highest (along z, the usual build direction), each along the facet's inward normal, as
//! deep as the skin, the blend, a voxel and half a hole.

use crate::error::Result;
use crate::field::{intersection_clearance, smooth_min, union_clearance, Aabb, Field, Vec3};
use crate::geom::Mesh;
use crate::grid::{distance_clearance, Grid, GridSpec, SPARE_VOXELS};
use crate::mesh::pipeline::{Family, Solid, HALF_WIDTH};
use std::sync::Arc;

/// The part and the solids kept whole, as distance grids on one voxel size.
pub struct Shape {
    /// The part's signed distance.
    part: Grid,
    /// The solids kept whole.
    keep: Vec<Grid>,
    /// The box the filled part is meshed in: the part and the kept solids, grown by two voxels
    /// so that it never clips them.
    pub bounds: Aabb,
    /// The lower corner of the part and the kept solids (before growing): where cells start.
    pub corner: Vec3,
    /// Voxel edge, mm.
    pub voxel: f64,
    /// Drain holes: axis from the part's surface inward, and radius, mm.
    pub drains: Vec<Drain>,
}

/// A drain hole: a capsule around the segment `from`–`to` of radius `radius`, mm.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Drain {
    /// Where the hole's axis meets the part's surface.
    pub from: Vec3,
    /// The end of the axis inside the part.
    pub to: Vec3,
    /// The hole's radius.
    pub radius: f64,
}

impl Drain {
    /// Signed distance to the hole (negative inside).
    pub(crate) fn distance(&self, p: Vec3) -> f64 {
        use crate::geom::{dot, sub};
        let (ab, ap) = (sub(self.to, self.from), sub(p, self.from));
        let t = (dot(ap, ab) / dot(ab, ab)).clamp(0.0, 1.0);
        let q = [0, 1, 2].map(|a| ap[a] - t * ab[a]);
        dot(q, q).sqrt() - self.radius
    }

    /// Holes of `diameter` reaching `depth` and half a hole into `part`: at its lowest and
    /// highest facet along z, along their inward normals.
    pub fn at_ends(part: &Mesh, diameter: f64, depth: f64) -> Vec<Drain> {
        use crate::geom::{cross, norm, sub};
        let tris: Vec<[Vec3; 3]> = (0..part.triangle_count())
            .map(|t| {
                [0, 1, 2].map(|k| {
                    let v = part.indices[3 * t + k] as usize;
                    [0, 1, 2].map(|a| part.positions[3 * v + a] as f64)
                })
            })
            .collect();
        let lowest = tris.iter().min_by(|a, b| {
            let top = |t: &[Vec3; 3]| t.iter().map(|v| v[2]).fold(f64::NEG_INFINITY, f64::max);
            top(a).total_cmp(&top(b))
        });
        let highest = tris.iter().max_by(|a, b| {
            let bottom = |t: &[Vec3; 3]| t.iter().map(|v| v[2]).fold(f64::INFINITY, f64::min);
            bottom(a).total_cmp(&bottom(b))
        });
        [lowest, highest]
            .into_iter()
            .flatten()
            .filter_map(|t| {
                let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
                let l = norm(n);
                (l > 0.0).then(|| {
                    let from = [0, 1, 2].map(|a| (t[0][a] + t[1][a] + t[2][a]) / 3.0);
                    let reach = depth + 0.5 * diameter;
                    Drain {
                        from,
                        to: [0, 1, 2].map(|a| from[a] - reach * n[a] / l),
                        radius: 0.5 * diameter,
                    }
                })
            })
            .collect()
    }
}

impl Shape {
    /// The distance grids of `part` and the solids `keep` at `voxel` mm, exact to `depth` mm
    /// inside the part (the skin and the blend) and over the narrow band.
    pub fn new(part: &Mesh, keep: &[Mesh], voxel: f64, depth: f64) -> Result<Shape> {
        let exterior = HALF_WIDTH + SPARE_VOXELS;
        let interior = depth / voxel + HALF_WIDTH + SPARE_VOXELS;
        let grid = Grid::distance_to_mesh(part, voxel, exterior, interior)?;
        let mut bounds = part.bounds().expect("a part has triangles");
        let mut grids = Vec::with_capacity(keep.len());
        for k in keep {
            grids.push(Grid::distance_to_mesh(k, voxel, exterior, exterior)?);
            let b = k.bounds().expect("a kept solid has triangles");
            for a in 0..3 {
                bounds.min[a] = bounds.min[a].min(b.min[a]);
                bounds.max[a] = bounds.max[a].max(b.max[a]);
            }
        }
        Ok(Shape {
            part: grid,
            keep: grids,
            corner: bounds.min,
            bounds: bounds.grown(2.0 * voxel),
            voxel,
            drains: Vec::new(),
        })
    }

    /// How deep `p` lies inside the part, mm (negative outside): exact down to the depth the
    /// grid was built for, within the grid's interpolation.
    pub fn depth(&self, p: Vec3) -> f64 {
        -self.part.value_at(p)
    }

    /// Whether the box `b` lies wholly `below` mm or more inside the part's surface, clear of
    /// the kept solids and the drain holes (from the distances at its centre, each 1-Lipschitz).
    pub fn holds(&self, b: &Aabb, below: f64) -> bool {
        let c = b.centre();
        let s = b.size();
        let r = 0.5 * (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
        self.depth(c) - r >= below
            && self.keep.iter().all(|g| g.value_at(c) >= r)
            && self.drilled(c) >= r
    }

    /// The distance to the drain holes (negative inside one; infinite without holes).
    fn drilled(&self, p: Vec3) -> f64 {
        self.drains
            .iter()
            .map(|d| d.distance(p))
            .fold(f64::INFINITY, f64::min)
    }

    /// Memory of the distance grids, bytes (OpenVDB's count).
    pub fn memory_bytes(&self) -> u64 {
        self.part.memory_bytes() + self.keep.iter().map(Grid::memory_bytes).sum::<u64>()
    }
}

/// What fills the part's core.
#[derive(Debug, Clone)]
pub enum Infill<S> {
    /// Nothing: the skin (and the kept solids) alone.
    Empty,
    /// Solid: the whole part.
    Full,
    /// A lattice.
    Lattice(S),
}

/// A part filled with a lattice, clipped by the shape's box.
#[derive(Clone)]
pub struct FillSolid<S> {
    /// The part and the kept solids.
    pub shape: Arc<Shape>,
    /// Skin thickness, mm (0: no skin, the lattice cut by the part's surface).
    pub skin: f64,
    /// Radius of the smooth minimum joining the lattice to the skin, mm (0: a sharp union).
    pub blend: f64,
    /// What fills the core.
    pub infill: Infill<S>,
}

impl<S: Solid + Clone> Solid for FillSolid<S> {
    fn field(&self, spec: &GridSpec) -> Box<dyn Field + '_> {
        Box::new(FillField {
            solid: self,
            lattice: match &self.infill {
                Infill::Lattice(l) => Some(l.field(spec)),
                _ => None,
            },
        })
    }

    fn bounds(&self) -> Aabb {
        self.shape.bounds
    }

    fn with_bounds(&self, _: Aabb) -> Self {
        // A filled part is never cut into templates (it has no period).
        self.clone()
    }

    fn period(&self) -> Option<Vec3> {
        None
    }

    fn snaps(&self) -> bool {
        false
    }
}

/// The field of a [`FillSolid`].
struct FillField<'a, S> {
    solid: &'a FillSolid<S>,
    lattice: Option<Box<dyn Field + 'a>>,
}

impl<S: Solid> FillField<'_, S> {
    /// The filled part's value from the part's distance `p`, the lattice's value `l` and the
    /// kept solids' distance `k`.
    fn combine(&self, p: f64, l: f64, k: f64) -> f64 {
        let s = self.solid;
        let inner = match &s.infill {
            Infill::Full => p,
            Infill::Empty => p.max(-p - s.skin),
            Infill::Lattice(_) if s.skin == 0.0 => p.max(l),
            Infill::Lattice(_) if s.blend > 0.0 => p.max(smooth_min(-p - s.skin, l, s.blend)),
            Infill::Lattice(_) => p.max((-p - s.skin).min(l)),
        };
        inner.min(k)
    }

    fn kept(&self, p: Vec3) -> f64 {
        self.solid
            .shape
            .keep
            .iter()
            .map(|g| g.value_at(p))
            .fold(f64::INFINITY, f64::min)
    }
}

impl<S: Solid> Field for FillField<'_, S> {
    fn value(&self, x: Vec3) -> f64 {
        self.undrilled_value(x).max(-self.solid.shape.drilled(x))
    }

    fn clearance(&self, x: Vec3) -> f64 {
        let c = self.undrilled_clearance(x);
        if self.solid.shape.drains.is_empty() {
            return c;
        }
        let v = self.undrilled_value(x);
        let d = self.solid.shape.drilled(x);
        intersection_clearance(v, c, -d, d.abs())
    }

    fn sample_block(&self, origin: Vec3, h: f64, out: &mut [f32; 512]) {
        self.undrilled_block(origin, h, out);
        if self.solid.shape.drains.is_empty() {
            return;
        }
        for i in 0..8 {
            for j in 0..8 {
                for k in 0..8 {
                    let p = [i, j, k].map(|a| a as f64 * h);
                    let x = [origin[0] + p[0], origin[1] + p[1], origin[2] + p[2]];
                    let o = &mut out[(i * 8 + j) * 8 + k];
                    *o = o.max(-self.solid.shape.drilled(x) as f32);
                }
            }
        }
    }
}

/// The solid inside a part filled with a skin and a lattice — the skin where `core` (the depth
/// below the skin, negative within it) is negative, or the lattice where `l` is, joined by a
/// smooth minimum of radius `blend` — as a value and a clearance, from each one's value and
/// clearance.
pub(crate) fn skin_or_lattice(
    (core, c_core): (f64, f64),
    (l, cl): (f64, f64),
    skin: f64,
    blend: f64,
) -> (f64, f64) {
    if skin == 0.0 {
        return (l, cl);
    }
    let c = union_clearance(core, c_core, l, cl);
    // The smooth minimum moves the surface by up to its radius.
    if blend > 0.0 {
        (smooth_min(core, l, blend), (c - blend).max(0.0))
    } else {
        (core.min(l), c)
    }
}

impl<S: Solid> FillField<'_, S> {
    /// The part's value before the drain holes.
    fn undrilled_value(&self, x: Vec3) -> f64 {
        let p = self.solid.shape.part.value_at(x);
        let l = self.lattice.as_ref().map_or(f64::INFINITY, |f| f.value(x));
        self.combine(p, l, self.kept(x))
    }

    fn undrilled_clearance(&self, x: Vec3) -> f64 {
        let s = self.solid;
        let p = s.shape.part.value_at(x);
        let h = s.shape.voxel;
        let cp = distance_clearance(p, h);
        let inner = match &s.infill {
            Infill::Full => cp,
            Infill::Empty => {
                let core = -p - s.skin;
                intersection_clearance(p, cp, core, distance_clearance(core, h))
            }
            Infill::Lattice(_) => {
                let f = self.lattice.as_ref().expect("a lattice has a field");
                let (l, cl) = (f.value(x), f.clearance(x));
                let core = -p - s.skin;
                let (sv, cs) = skin_or_lattice(
                    (core, distance_clearance(core, h)),
                    (l, cl),
                    s.skin,
                    s.blend,
                );
                intersection_clearance(p, cp, sv, cs)
            }
        };
        if s.shape.keep.is_empty() {
            return inner;
        }
        let k = self.kept(x);
        // The inner value's sign, for the union's rule: that of the part as filled.
        let v = self.combine(
            p,
            self.lattice.as_ref().map_or(f64::INFINITY, |f| f.value(x)),
            f64::INFINITY,
        );
        union_clearance(v, inner, k, distance_clearance(k, h))
    }

    fn undrilled_block(&self, origin: Vec3, h: f64, out: &mut [f32; 512]) {
        let mut points = [0.0f64; 3 * 512];
        for i in 0..8 {
            for j in 0..8 {
                for k in 0..8 {
                    let n = 3 * ((i * 8 + j) * 8 + k);
                    points[n] = origin[0] + h * i as f64;
                    points[n + 1] = origin[1] + h * j as f64;
                    points[n + 2] = origin[2] + h * k as f64;
                }
            }
        }
        let mut part = [0.0f32; 512];
        self.solid.shape.part.probe(&points, &mut part);
        let mut lattice = [f32::INFINITY; 512];
        if let Some(f) = &self.lattice {
            f.sample_block(origin, h, &mut lattice);
        }
        let mut kept = [f32::INFINITY; 512];
        let mut one = [0.0f32; 512];
        for g in &self.solid.shape.keep {
            g.probe(&points, &mut one);
            for (k, o) in kept.iter_mut().zip(one.iter()) {
                *k = k.min(*o);
            }
        }
        for n in 0..512 {
            out[n] = self.combine(part[n] as f64, lattice[n] as f64, kept[n] as f64) as f32;
        }
    }
}

/// A filled part at every lattice level: the lattice's family (`F`) inside the part, its
/// density measured on the region the lattice fills.
pub struct FillFamily<F: Family> {
    /// The lattice's family, over the shape's box.
    pub lattice: F,
    /// The filled part at some level (the infill is replaced).
    pub part: FillSolid<F::Solid>,
    /// Volume of the part with nothing in its core (the skin and kept solids), mm³.
    pub base_volume: f64,
    /// Volume of the region the lattice fills (the whole part's less the base), mm³.
    pub fill_volume: f64,
}

impl<F: Family> Family for FillFamily<F>
where
    F::Solid: Clone,
{
    type Solid = FillSolid<F::Solid>;

    fn at(&self, level: f64) -> Self::Solid {
        FillSolid {
            infill: Infill::Lattice(self.lattice.at(level)),
            ..self.part.clone()
        }
    }

    fn model_fraction(&self, level: f64) -> f64 {
        self.lattice.model_fraction(level)
    }

    fn model_level(&self, fraction: f64) -> f64 {
        self.lattice.model_level(fraction)
    }

    /// The lattice's share of the region it fills.
    fn fraction(&self, volume: f64, _: &Aabb) -> f64 {
        (volume - self.base_volume) / self.fill_volume
    }
}
