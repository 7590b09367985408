//! A Voronoi foam as a family of solids for the pipeline: the level is the strut radius of a net
//! or the wall thickness of a sheet.
//!
//! **Net.** Every Voronoi edge near the box is a capsule of the radius ([`BeamField`]: exact
//! distance to the edges, minus the radius).
//!
//! **Sheet.** For a point `p` in the cell of seed `s₁`, its distance to the cell's boundary — to
//! the nearest Voronoi face — is the least distance to the bisector planes of `s₁` and the other
//! seeds, `(|p − sⱼ|² − |p − s₁|²) / (2 |sⱼ − s₁|)`: a convex cell is the intersection of those
//! half spaces, and a redundant plane lies outside the cell, never nearer. Only seeds with
//! `|p − sⱼ| ≤ |p − s₁| + 2D` can give a distance under `D` (the plane is at least half the
//! difference of the two distances away), so a kd-tree query of that radius finds them all. The
//! wall is where that distance is under half the thickness; its field is exact, 1-Lipschitz.
//!
//! The density model samples points through the box and the level at which each is held
//! ([`LevelModel`]). The largest level keeps the pores open. A net's window shuts when the struts
//! round it reach its centroid (its inradius, from the centroid); half the windows in the box
//! may shut, no more: each cell keeps several windows on average and the void runs through the
//! foam. A sheet's cells are closed by their walls; the walls may be as thick as half the
//! distance from a seed to its nearest face, leaving nine cells in ten a void at least half that
//! size.

use super::diagram::Voronoi;
use super::seeds::{wrap, Rng};
use crate::error::{Error, Result};
use crate::field::beams::{segment_distance, Beam, BeamField, Cap};
use crate::field::periodic::{block_axis, samples_per_cell};
use crate::field::{Aabb, Field, Vec3};
use crate::grid::GridSpec;
use crate::io::threemf::BeamModel;
use crate::lattice::model::LevelModel;
use crate::lattice::strut::beams::segment_box_distance;
use crate::mesh::graded::LevelGrid;
use crate::mesh::pipeline::{Family, Solid};
use kiddo::{KdTree, SquaredEuclidean};
use std::collections::HashMap;
use std::sync::{Arc, OnceLock};

/// Points of the density model.
const MODEL_POINTS: usize = 1 << 16;

/// What the foam's members are.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Structure {
    /// Struts along the Voronoi edges.
    Net,
    /// Walls along the Voronoi faces.
    Sheet,
}

impl Structure {
    /// The name of its level, for messages: "radius" or "thickness".
    pub fn level_name(self) -> &'static str {
        match self {
            Structure::Net => "radius",
            Structure::Sheet => "thickness",
        }
    }
}

/// Mean, spread and extremes of a set of lengths, mm.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct Spread {
    /// How many.
    pub count: usize,
    /// Mean.
    pub mean: f64,
    /// 5th percentile.
    pub p5: f64,
    /// 95th percentile.
    pub p95: f64,
    /// Smallest.
    pub min: f64,
    /// Largest.
    pub max: f64,
}

impl Spread {
    /// The spread of `values`.
    pub fn of(mut values: Vec<f64>) -> Spread {
        values.retain(|v| v.is_finite());
        if values.is_empty() {
            return Spread::default();
        }
        values.sort_by(f64::total_cmp);
        let at = |q: f64| {
            values[((q * (values.len() - 1) as f64).round() as usize).min(values.len() - 1)]
        };
        Spread {
            count: values.len(),
            mean: values.iter().sum::<f64>() / values.len() as f64,
            p5: at(0.05),
            p95: at(0.95),
            min: values[0],
            max: values[values.len() - 1],
        }
    }
}

/// The foam's diagram, measured.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct FoamStats {
    /// Seeds the diagram was made of (the box and a margin round it).
    pub seeds: usize,
    /// Cells in the box: seeds inside it.
    pub cells: usize,
    /// Equivalent diameters of the cells in the box (a ball of the cell's volume), mm.
    pub cell_diameter: Spread,
    /// Lengths of the Voronoi edges whose middle is in the box, mm (after edges shorter than
    /// the merge length were merged away).
    pub edge_length: Spread,
    /// Voronoi edges merged away as shorter than the merge length.
    pub edges_merged: usize,
    /// A sheet's walls in the box with a pore through them (`--pores`).
    pub pores: usize,
}

/// A Voronoi foam in a box.
pub struct Foam {
    /// Struts or walls.
    pub structure: Structure,
    /// The part's box.
    pub bounds: Aabb,
    /// The diagram, its short edges merged.
    pub diagram: Voronoi,
    /// The edges that can reach into the box.
    segments: Vec<[Vec3; 2]>,
    /// The seeds, for the walls' field.
    tree: KdTree<f64, 3>,
    /// Volume fraction against the level, measured when first asked for (a periodic net's
    /// strut lattice has its own).
    model: OnceLock<LevelModel>,
    /// The largest level at which the pores stay open.
    pub closing: f64,
    /// The diagram measured.
    pub stats: FoamStats,
    /// How far beyond the box a member may matter, mm.
    reach: f64,
    /// The cell the foam repeats with, from the box's lower corner (a periodic foam: its box is
    /// that cell, and its seeds the cell's followed by their copies in the 26 cells round it).
    pub period: Option<Vec3>,
    /// A sheet's pores: a round hole through each wall, by the pair of seeds the wall is
    /// between.
    pores: HashMap<(u32, u32), Pore>,
}

/// A round hole through a wall: its centre (the face's centroid), the wall's unit normal and
/// its radius, mm.
#[derive(Debug, Clone, Copy)]
pub struct Pore {
    /// The face's centroid.
    pub centre: Vec3,
    /// The wall's unit normal.
    pub normal: Vec3,
    /// The hole's radius.
    pub radius: f64,
}

impl Pore {
    /// Positive inside the hole (within its radius of the axis and `depth` of the face), the
    /// least distance to leaving it.
    fn inside(&self, p: Vec3, depth: f64) -> f64 {
        let v = sub(p, self.centre);
        let a = (0..3).map(|k| v[k] * self.normal[k]).sum::<f64>();
        let r = (norm(v).powi(2) - a * a).max(0.0).sqrt();
        (self.radius - r).min(depth - a.abs())
    }
}

impl std::fmt::Debug for Foam {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Foam")
            .field("structure", &self.structure)
            .field("bounds", &self.bounds)
            .field("stats", &self.stats)
            .finish()
    }
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm(a: Vec3) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

impl Foam {
    /// The foam of `seeds` (which should fill `bounds` and a margin of a few spacings round it)
    /// in `bounds`, edges shorter than `merge` mm merged; `reach` is how far beyond the box a
    /// member may matter (its largest radius or half thickness and the narrow band).
    pub fn new(
        structure: Structure,
        bounds: Aabb,
        seeds: Vec<Vec3>,
        merge: f64,
        reach: f64,
    ) -> Result<Foam> {
        if seeds.iter().filter(|s| bounds.contains(**s)).count() == 0 {
            return Err(Error::invalid(
                "no seed lies in the box: the foam has no cell there",
            ));
        }
        let raw = Voronoi::of(&seeds)?;
        let diagram = raw.merged(merge);
        let near = bounds.grown(reach);
        let segments: Vec<[Vec3; 2]> = diagram
            .edges
            .iter()
            .map(|&[a, b]| [diagram.vertices[a as usize], diagram.vertices[b as usize]])
            .filter(|[a, b]| {
                let lo = [0, 1, 2].map(|k| a[k].min(b[k]));
                let hi = [0, 1, 2].map(|k| a[k].max(b[k]));
                (0..3).all(|k| lo[k] <= near.max[k] && hi[k] >= near.min[k])
            })
            .collect();
        let mut tree: KdTree<f64, 3> = KdTree::with_capacity(seeds.len());
        for (i, s) in seeds.iter().enumerate() {
            tree.add(s, i as u64);
        }
        let stats = FoamStats {
            seeds: seeds.len(),
            cells: seeds.iter().filter(|s| bounds.contains(**s)).count(),
            cell_diameter: Spread::of(
                raw.cell_volumes()
                    .iter()
                    .zip(&seeds)
                    .filter(|(v, s)| **v > 0.0 && bounds.contains(**s))
                    .map(|(v, _)| (6.0 * v / std::f64::consts::PI).cbrt())
                    .collect(),
            ),
            edge_length: Spread::of(
                diagram
                    .edges
                    .iter()
                    .map(|&[a, b]| (diagram.vertices[a as usize], diagram.vertices[b as usize]))
                    .filter(|(a, b)| bounds.contains([0, 1, 2].map(|k| 0.5 * (a[k] + b[k]))))
                    .map(|(a, b)| norm(sub(a, b)))
                    .collect(),
            ),
            edges_merged: raw.edges.len() - diagram.edges.len(),
            pores: 0,
        };
        let mut foam = Foam {
            structure,
            bounds,
            diagram,
            segments,
            tree,
            model: OnceLock::new(),
            closing: 0.0,
            stats,
            reach,
            period: None,
            pores: HashMap::new(),
        };
        foam.closing = foam.closing_level();
        Ok(foam)
    }

    /// The seeds.
    pub fn seeds(&self) -> &[Vec3] {
        &self.diagram.seeds
    }

    /// The foam made on a cell that repeats with `size` (its seeds the cell's, then their
    /// copies round it, as [`super::periodic::with_copies`] gives them).
    pub fn repeating(self, size: Vec3) -> Foam {
        Foam {
            period: Some(size),
            ..self
        }
    }

    /// The foam with a round pore through each wall of a sheet, its radius `fraction` of the
    /// face's inradius (from its centroid); none where that is under `least` mm. The density
    /// model is measured with them.
    pub fn with_pores(mut self, fraction: f64, least: f64) -> Foam {
        let d = &self.diagram;
        let near = self.bounds.grown(self.reach);
        let mut pores = HashMap::new();
        for f in &d.faces {
            let pts: Vec<Vec3> = f.vertices.iter().map(|&v| d.vertices[v as usize]).collect();
            let n = pts.len() as f64;
            let c = [0, 1, 2].map(|k| pts.iter().map(|p| p[k]).sum::<f64>() / n);
            if !near.contains(c) {
                continue;
            }
            let inradius = (0..pts.len())
                .map(|i| segment_distance(c, pts[i], pts[(i + 1) % pts.len()]))
                .fold(f64::INFINITY, f64::min);
            let radius = fraction * inradius;
            let axis = sub(d.seeds[f.seeds[1] as usize], d.seeds[f.seeds[0] as usize]);
            let len = norm(axis);
            if radius < least || len <= 0.0 {
                continue;
            }
            let key = (f.seeds[0].min(f.seeds[1]), f.seeds[0].max(f.seeds[1]));
            pores.insert(
                key,
                Pore {
                    centre: c,
                    normal: axis.map(|x| x / len),
                    radius,
                },
            );
        }
        self.stats.pores = pores
            .values()
            .filter(|p: &&Pore| self.bounds.contains(p.centre))
            .count();
        self.pores = pores;
        self.model = OnceLock::new();
        self
    }

    /// The volume fraction against the level (see the module's notes).
    pub fn model(&self) -> &LevelModel {
        self.model.get_or_init(|| self.measure_model())
    }

    /// The pores through the walls.
    pub fn pores(&self) -> impl Iterator<Item = &Pore> {
        self.pores.values()
    }

    /// The pores through the walls, each with the indices of the two seeds (lower first)
    /// whose wall it opens.
    pub fn pore_pairs(&self) -> impl Iterator<Item = ((u32, u32), &Pore)> {
        self.pores.iter().map(|(k, p)| (*k, p))
    }

    /// The seed nearest `p`: its index and distance.
    pub fn nearest_seed(&self, p: Vec3) -> (u32, f64) {
        let n = self.tree.nearest_one::<SquaredEuclidean>(&p);
        (n.item as u32, n.distance.sqrt())
    }

    /// The indices of the seeds within `r` of `p`, in increasing order.
    pub fn seeds_within(&self, p: Vec3, r: f64) -> Vec<u32> {
        let mut found: Vec<u32> = self
            .tree
            .within_unsorted::<SquaredEuclidean>(&p, r * r)
            .iter()
            .map(|n| n.item as u32)
            .collect();
        found.sort_unstable();
        found
    }

    /// The seeds that make the foam: all of them, or a periodic foam's cell's own.
    pub fn own_seeds(&self) -> &[Vec3] {
        let s = &self.diagram.seeds;
        match self.period {
            Some(_) => &s[..s.len() / 27],
            None => s,
        }
    }

    /// The edges that reach into the box, as segments.
    pub fn segments(&self) -> &[[Vec3; 2]] {
        &self.segments
    }

    /// The net's struts at `radius` as beams (capsules).
    pub fn beams(&self, radius: f64) -> Vec<Beam> {
        self.segments
            .iter()
            .map(|&ends| Beam {
                ends,
                radii: [radius; 2],
                caps: [Cap::Sphere; 2],
            })
            .collect()
    }

    /// The net as 3MF beams of `radius`: the Voronoi edges that reach into the box, their ends
    /// shared, the box their clipping mesh.
    pub fn beam_model(&self, radius: f64) -> BeamModel {
        let d = &self.diagram;
        let near = self.bounds.grown(radius);
        let mut model = BeamModel {
            radius,
            min_length: 1e-4,
            clip: Some(self.bounds),
            ..BeamModel::default()
        };
        let mut index = vec![u32::MAX; d.vertices.len()];
        for &[a, b] in &d.edges {
            let (p, q) = (d.vertices[a as usize], d.vertices[b as usize]);
            let reaches =
                (0..3).all(|k| p[k].min(q[k]) <= near.max[k] && p[k].max(q[k]) >= near.min[k]);
            if !reaches || segment_box_distance(p, q, &self.bounds) > radius {
                continue;
            }
            let ends = [a, b].map(|v| {
                if index[v as usize] == u32::MAX {
                    index[v as usize] = model.vertices.len() as u32;
                    model.vertices.push(d.vertices[v as usize]);
                }
                index[v as usize]
            });
            model.beams.push((ends, [radius; 2]));
        }
        model
    }

    /// The net's field at `radius`, exact within `reach` of the struts.
    pub fn net_field(&self, radius: f64, reach: f64) -> BeamField {
        BeamField::new(&self.beams(radius), &[], reach)
    }

    /// The distance from `p` to the nearest Voronoi face, up to `cap`, and that face's pore
    /// when it has one.
    pub fn face_distance(&self, p: Vec3, cap: f64) -> (f64, Option<&Pore>) {
        let nn = self.tree.nearest_one::<SquaredEuclidean>(&p);
        let s1 = self.diagram.seeds[nn.item as usize];
        let a2 = nn.distance;
        let r = a2.sqrt() + 2.0 * cap;
        let (mut d, mut other) = (cap, None);
        for nb in self.tree.within_unsorted::<SquaredEuclidean>(&p, r * r) {
            if nb.item == nn.item {
                continue;
            }
            let c = norm(sub(self.diagram.seeds[nb.item as usize], s1));
            if c > 0.0 && (nb.distance - a2) / (2.0 * c) < d {
                d = (nb.distance - a2) / (2.0 * c);
                other = Some(nb.item as u32);
            }
        }
        (d.max(0.0), other.and_then(|j| self.pore(nn.item as u32, j)))
    }

    /// The pore through the wall between seeds `i` and `j`.
    fn pore(&self, i: u32, j: u32) -> Option<&Pore> {
        if self.pores.is_empty() {
            return None;
        }
        self.pores.get(&(i.min(j), i.max(j)))
    }

    /// The level at which the solid holds the point `p` (never, within a pore's radius of its
    /// axis).
    fn level_holding(&self, p: Vec3, skeleton: &BeamField) -> f64 {
        match self.structure {
            Structure::Net => skeleton.value(p).max(0.0),
            Structure::Sheet => match self.face_distance(p, self.reach) {
                (_, Some(pore)) if pore.inside(p, f64::INFINITY) > 0.0 => self.reach,
                (d, _) => 2.0 * d,
            },
        }
    }

    fn measure_model(&self) -> LevelModel {
        self.model_in(&self.bounds)
    }

    /// The volume fraction against the level of the foam in `region` (a part of its box), as
    /// [`Foam::model`] measures the box's.
    pub fn model_in(&self, region: &Aabb) -> LevelModel {
        use rayon::prelude::*;
        let size = region.size();
        let far = self.reach;
        let skeleton = match self.structure {
            Structure::Net => self.net_field(0.0, far),
            Structure::Sheet => BeamField::new(&[], &[], 0.0),
        };
        let mut rng = Rng::new(0x5eed);
        let points: Vec<Vec3> = (0..MODEL_POINTS)
            .map(|_| [0, 1, 2].map(|k| region.min[k] + rng.unit() * size[k]))
            .collect();
        let levels: Vec<f64> = points
            .par_iter()
            .map(|&p| self.level_holding(p, &skeleton))
            .collect();
        LevelModel::new(levels, far)
    }

    /// The largest level at which the pores stay open (see the module's notes).
    fn closing_level(&self) -> f64 {
        let d = &self.diagram;
        let inside = |i: u32| self.bounds.contains(d.seeds[i as usize]);
        let cells = (0..d.seeds.len() as u32).filter(|&i| inside(i)).count();
        if cells == 0 {
            return 0.0;
        }
        match self.structure {
            // Half the windows in the box stay open: a window shuts when the struts round it
            // reach its centroid (its inradius, from the centroid).
            Structure::Net => {
                let mut widths: Vec<f64> = d
                    .faces
                    .iter()
                    .filter_map(|f| {
                        let pts: Vec<Vec3> =
                            f.vertices.iter().map(|&v| d.vertices[v as usize]).collect();
                        let n = pts.len() as f64;
                        let c = [0, 1, 2].map(|k| pts.iter().map(|p| p[k]).sum::<f64>() / n);
                        self.bounds.contains(c).then(|| {
                            (0..pts.len())
                                .map(|i| segment_distance(c, pts[i], pts[(i + 1) % pts.len()]))
                                .fold(f64::INFINITY, f64::min)
                        })
                    })
                    .collect();
                if widths.is_empty() {
                    return 0.0;
                }
                widths.sort_by(f64::total_cmp);
                widths[widths.len() / 2]
            }
            // A cell's void is gone when its walls reach its middle: its nearest face is the
            // bisector with the nearest other seed, half their distance away; walls half that
            // thick leave the void at least half its inradius.
            Structure::Sheet => {
                let mut open: Vec<f64> = (0..d.seeds.len() as u32)
                    .filter(|&i| inside(i))
                    .map(|i| {
                        let s = d.seeds[i as usize];
                        self.tree
                            .nearest_n::<SquaredEuclidean>(&s, 2)
                            .iter()
                            .filter(|n| n.item != i as u64)
                            .map(|n| 0.5 * n.distance.sqrt())
                            .fold(f64::INFINITY, f64::min)
                    })
                    .filter(|x| x.is_finite())
                    .collect();
                if open.is_empty() {
                    return 0.0;
                }
                open.sort_by(f64::total_cmp);
                open[open.len() / 10]
            }
        }
    }
}

/// A foam at one level, clipped by a box.
#[derive(Debug, Clone)]
pub struct FoamSolid {
    /// The foam.
    pub foam: Arc<Foam>,
    /// Strut radius or wall thickness, mm.
    pub level: f64,
    /// The clipping box.
    pub bounds: Aabb,
}

/// Half a wall's thickness at a point: the same everywhere, or half the level a grid gives
/// there (a graded sheet).
#[derive(Clone, Copy)]
pub(super) enum Half<'a> {
    /// The same everywhere, mm.
    Uniform(f64),
    /// Half the grid's level plus `offset`.
    Graded {
        /// The level at each point.
        levels: &'a LevelGrid,
        /// Added to it.
        offset: f64,
    },
}

impl Half<'_> {
    fn at(&self, p: Vec3) -> f64 {
        match *self {
            Half::Uniform(h) => h,
            Half::Graded { levels, offset } => 0.5 * (levels.at(p).0 + offset).max(0.0),
        }
    }

    /// The most it is anywhere.
    fn most(&self) -> f64 {
        match *self {
            Half::Uniform(h) => h,
            Half::Graded { levels, offset } => 0.5 * (levels.max + offset).max(0.0),
        }
    }
}

/// The walls' field: distance to the nearest face minus half the thickness, clamped at `reach`;
/// `lipschitz` bounds its slope (1, or more where the thickness varies), for its clearance.
pub(super) struct SheetField<'a> {
    pub(super) foam: &'a Foam,
    pub(super) half: Half<'a>,
    pub(super) reach: f64,
    pub(super) lipschitz: f64,
}

impl SheetField<'_> {
    /// Values at `points`, all within `spread` of `centre`: the seeds that can matter to any
    /// of them found once.
    fn values_near(&self, centre: Vec3, spread: f64, points: &[Vec3], out: &mut [f64]) {
        let tree = &self.foam.tree;
        let seeds = &self.foam.diagram.seeds;
        let cap = self.half.most() + self.reach;
        let a = tree
            .nearest_one::<SquaredEuclidean>(&centre)
            .distance
            .sqrt();
        let r = a + 2.0 * spread + 2.0 * cap;
        let found = tree.within_unsorted::<SquaredEuclidean>(&centre, r * r);
        let near: Vec<Vec3> = found.iter().map(|n| seeds[n.item as usize]).collect();
        let index: Vec<u32> = found.iter().map(|n| n.item as u32).collect();
        let d2 = |p: Vec3, s: Vec3| (0..3).map(|k| (p[k] - s[k]).powi(2)).sum::<f64>();
        for (p, o) in points.iter().zip(out.iter_mut()) {
            let (mut best, mut i1) = (f64::INFINITY, 0);
            for (i, s) in near.iter().enumerate() {
                let d = d2(*p, *s);
                if d < best {
                    best = d;
                    i1 = i;
                }
            }
            let s1 = near[i1];
            let (mut d, mut other) = (cap, None);
            for (i, s) in near.iter().enumerate() {
                if i != i1 {
                    let c = d2(*s, s1).sqrt();
                    if c > 0.0 && (d2(*p, *s) - best) / (2.0 * c) < d {
                        d = (d2(*p, *s) - best) / (2.0 * c);
                        other = Some(i);
                    }
                }
            }
            let half = self.half.at(*p);
            let wall = d - half;
            // A pore cuts the wall through, and the narrow band beyond it.
            let hole = other
                .and_then(|j| self.foam.pore(index[i1], index[j]))
                .map_or(f64::NEG_INFINITY, |pore| pore.inside(*p, half + self.reach));
            *o = wall.max(hole).min(self.reach);
        }
    }
}

impl Field for SheetField<'_> {
    fn value(&self, p: Vec3) -> f64 {
        let mut out = [0.0];
        self.values_near(p, 0.0, &[p], &mut out);
        out[0]
    }

    fn clearance(&self, p: Vec3) -> f64 {
        self.value(p).abs() / self.lipschitz
    }

    /// Not where a pore cuts its wall: its rim is a crease that snapping would fold.
    fn smooth_near(&self, p: Vec3, reach: f64) -> bool {
        let half = self.half.most();
        match self.foam.face_distance(p, half + self.reach) {
            (_, Some(pore)) => pore.inside(p, half + reach) < -reach,
            _ => true,
        }
    }

    fn values(&self, points: &[Vec3], out: &mut [f64]) {
        if points.is_empty() {
            return;
        }
        let n = points.len() as f64;
        let c = [0, 1, 2].map(|k| points.iter().map(|p| p[k]).sum::<f64>() / n);
        let spread = points.iter().map(|p| norm(sub(*p, c))).fold(0.0, f64::max);
        self.values_near(c, spread, points, out);
    }

    fn sample_block(&self, origin: Vec3, h: f64, out: &mut [f32; 512]) {
        let mut points = Vec::with_capacity(512);
        for i in 0..8 {
            for j in 0..8 {
                for k in 0..8 {
                    points.push([
                        origin[0] + h * i as f64,
                        origin[1] + h * j as f64,
                        origin[2] + h * k as f64,
                    ]);
                }
            }
        }
        let c = origin.map(|x| x + 3.5 * h);
        let mut values = [0.0; 512];
        self.values_near(c, 3.5 * h * 3f64.sqrt(), &points, &mut values);
        for (o, v) in out.iter_mut().zip(values) {
            *o = v as f32;
        }
    }
}

/// A periodic foam's field: the cell's, at the point's place in the cell (by the sample's index
/// modulo the cell where the cell holds a whole number of voxels, so that samples a cell apart
/// are bit-identical).
struct Repeated<'a> {
    inner: Box<dyn Field + 'a>,
    cell: Aabb,
    samples: Option<([u32; 3], f64)>,
}

impl Field for Repeated<'_> {
    fn value(&self, p: Vec3) -> f64 {
        self.inner.value(wrap(p, &self.cell))
    }

    fn smooth_near(&self, p: Vec3, reach: f64) -> bool {
        self.inner.smooth_near(wrap(p, &self.cell), reach)
    }

    fn clearance(&self, p: Vec3) -> f64 {
        self.value(p).abs()
    }

    fn values(&self, points: &[Vec3], out: &mut [f64]) {
        let wrapped: Vec<Vec3> = points.iter().map(|&p| wrap(p, &self.cell)).collect();
        self.inner.values(&wrapped, out);
    }

    fn sample_block(&self, origin: Vec3, h: f64, out: &mut [f32; 512]) {
        let size = self.cell.size();
        let axis = |a: usize| {
            block_axis(self.samples, self.cell.min[a], size[a], origin[a], h, a)
                .map(|f| self.cell.min[a] + f * size[a])
        };
        let [x, y, z] = [axis(0), axis(1), axis(2)];
        let mut points = Vec::with_capacity(512);
        for &px in &x {
            for &py in &y {
                for &pz in &z {
                    points.push(wrap([px, py, pz], &self.cell));
                }
            }
        }
        let mut values = [0.0; 512];
        self.inner.values(&points, &mut values);
        for (o, v) in out.iter_mut().zip(values) {
            *o = v as f32;
        }
    }
}

impl FoamSolid {
    fn unrepeated(&self, reach: f64) -> Box<dyn Field + '_> {
        match self.foam.structure {
            Structure::Net => Box::new(self.foam.net_field(self.level, reach)),
            Structure::Sheet => Box::new(SheetField {
                foam: &self.foam,
                half: Half::Uniform(0.5 * self.level),
                reach,
                lipschitz: 1.0,
            }),
        }
    }
}

impl Solid for FoamSolid {
    fn field(&self, spec: &GridSpec) -> Box<dyn Field + '_> {
        let inner = self.unrepeated(spec.half_width * spec.voxel);
        match self.foam.period {
            Some(size) => Box::new(Repeated {
                inner,
                cell: self.foam.bounds,
                samples: samples_per_cell(size, spec.voxel),
            }),
            None => inner,
        }
    }

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn with_bounds(&self, bounds: Aabb) -> Self {
        FoamSolid {
            bounds,
            ..self.clone()
        }
    }

    fn period(&self) -> Option<Vec3> {
        self.foam
            .period
            .filter(|_| self.bounds.min == self.foam.bounds.min)
    }
}

/// A foam at every level, clipped by a box (the foam's own, or any box for a periodic foam).
#[derive(Debug, Clone)]
pub struct FoamFamily {
    /// The foam.
    pub foam: Arc<Foam>,
    /// The part's box.
    pub bounds: Aabb,
}

impl Family for FoamFamily {
    type Solid = FoamSolid;

    fn at(&self, level: f64) -> FoamSolid {
        FoamSolid {
            foam: self.foam.clone(),
            level,
            bounds: self.bounds,
        }
    }

    fn model_fraction(&self, level: f64) -> f64 {
        self.foam.model().fraction(level)
    }

    fn model_level(&self, fraction: f64) -> f64 {
        self.foam.model().level(fraction)
    }
}
