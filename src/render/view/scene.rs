//! A part as the editor's shader draws it: the numbers its uniforms and strut texture take.

use crate::field::{Aabb, Vec3};
use crate::geom::bvh::Bvh;
use crate::lattice::tpms::Structure;
use crate::lattice::voronoi::{FoamSolid, Structure as Foam};
use crate::render::{Lattice, Model};
use serde::Serialize;

/// How far above the part's radius the page's radius control reaches: the strut list is built
/// for that radius, so that every radius up to it draws every strut that reaches a cell.
pub const RADIUS_SPAN: f64 = 2.0;

/// What the page draws.
#[derive(Debug, Clone, Serialize)]
pub struct Scene {
    /// `"tpms"`, `"struts"` or `"walls"`.
    pub kind: &'static str,
    /// The clipping box, mm: lower and upper corner.
    pub bounds: [Vec3; 2],
    /// The voxel meshing would use, mm (normals are taken over a tenth of it).
    pub voxel: f64,
    /// The shortest cell side, mm.
    pub cell: f64,
    /// The TPMS level or the strut radius (mm) of the part's density.
    pub level: f64,
    /// The lattice's distances are exact up to this and capped at it, mm.
    pub reach: f64,
    /// A TPMS lattice's terms and cell.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tpms: Option<Tpms>,
    /// A strut lattice's augmented cell, or a Voronoi net's struts.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub struts: Option<Struts>,
    /// A Voronoi sheet's seeds.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub walls: Option<Walls>,
    /// For a filled part: its surface, skin, drains and kept solids (the lattice fills it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fill: Option<Fill>,
}

/// A triangle mesh under its BVH, as [`Bvh::nodes`] and the triangles' corners.
#[derive(Debug, Clone, Serialize)]
pub struct Triangles {
    /// Per node: lower corner, first child or triangle, upper corner, triangle count.
    pub nodes: Vec<[f32; 8]>,
    /// Per triangle: its three corners.
    pub triangles: Vec<[f32; 9]>,
}

impl Triangles {
    /// The BVH's nodes and triangles.
    pub fn of(bvh: &Bvh) -> Triangles {
        Triangles {
            nodes: bvh.nodes().iter().map(|n| n.map(|x| x as f32)).collect(),
            triangles: bvh
                .triangles()
                .iter()
                .map(|t| {
                    let c = t.as_flattened();
                    std::array::from_fn(|i| c[i] as f32)
                })
                .collect(),
        }
    }
}

/// A filled part: the lattice inside the part's surface, a skin of the surface's shape (the
/// depth below the surface from the BVH, capped where it stops mattering), less the drain
/// holes, with the kept solids.
#[derive(Debug, Clone, Serialize)]
pub struct Fill {
    /// The part's surface.
    pub part: Triangles,
    /// The kept solids, in one BVH (empty: none).
    pub keep: Triangles,
    /// Per drain hole: its axis' ends and its radius.
    pub drains: Vec<[f64; 7]>,
    /// Skin thickness, mm (0: the lattice alone).
    pub skin: f64,
    /// Blend radius between skin and lattice, mm.
    pub blend: f64,
    /// Depths are asked up to this, mm (skin, blend, the lattice's reach and a voxel).
    pub cap: f64,
}

/// `F = Σ coef · Π_a f_a(2π k_a u_a)` with `u` the cell coordinates from the phase.
#[derive(Debug, Clone, Serialize)]
pub struct Tpms {
    /// Per term: the coefficient and, per axis, `3k + f` (f: 0 one, 1 cos, 2 sin).
    pub terms: Vec<[f64; 4]>,
    /// Solid around the surface (`|F| ≤ t`) rather than on one side (`F ≤ t`).
    pub sheet: bool,
    /// Cell size per axis, mm.
    pub size: Vec3,
    /// A cell's lower corner, mm.
    pub phase: Vec3,
    /// A bound on |∇F| in mm⁻¹: `|F − t| / lipschitz` is a safe step.
    pub lipschitz: f64,
}

/// The struts of the augmented cell (the cell's own and every copy that comes within the
/// reach of it), in the cell's centred coordinates, listed per bin of the cell. A Voronoi net,
/// random through its box, is one cell that covers the box (a point of the box is its own
/// place in it, so no copy ever reaches the box).
#[derive(Debug, Clone, Serialize)]
pub struct Struts {
    /// Per strut of each bin in turn: `a`, its radius factor, `b`, its radius factor.
    pub struts: Vec<[f64; 8]>,
    /// Where each bin's struts start in `struts` (bin `(i·n₁ + j)·n₂ + k`), and their end.
    pub bins: Vec<u32>,
    /// Bins per axis, `n₀, n₁, n₂`: they split the cell into equal parts.
    pub bins_per_axis: [usize; 3],
    /// Joint blend radius, mm.
    pub blend: f64,
    /// The largest radius the list holds every strut for, mm.
    pub max_radius: f64,
    /// Cell size per axis, mm.
    pub size: Vec3,
    /// A cell's lower corner, mm.
    pub phase: Vec3,
}

/// A Voronoi sheet's walls, as the page finds them: the distance to the nearest face from the
/// nearest seed and the bisector planes with the others (`crate::lattice::voronoi`'s field).
/// The region drawn (a periodic foam's cell, which the page repeats, or the box) is split into
/// bins, each listing every seed that can be a point's nearest or bound its cell within the
/// reach of a wall as thick as [`RADIUS_SPAN`] times the part's, and every pore whose hole
/// comes within that of the bin.
#[derive(Debug, Clone, Serialize)]
pub struct Walls {
    /// Per seed of each bin in turn: its place from `phase`, mm, and its index.
    pub seeds: Vec<[f64; 4]>,
    /// Where each bin's seeds start in `seeds` (bin `(i·n₁ + j)·n₂ + k`), and their end.
    pub bins: Vec<u32>,
    /// Bins per axis, `n₀, n₁, n₂`.
    pub bins_per_axis: [usize; 3],
    /// Per pore of each bin in turn: its centre from `phase` and radius, its wall's unit
    /// normal, and the indices of the two seeds whose wall it opens (lower first).
    pub pores: Vec<[f64; 12]>,
    /// Where each bin's pores start in `pores`, and their end.
    pub pore_bins: Vec<u32>,
    /// The thickest wall the lists hold every seed for, mm.
    pub max_thickness: f64,
    /// The region's size per axis, mm.
    pub size: Vec3,
    /// Its lower corner, mm.
    pub phase: Vec3,
    /// Whether it repeats (a periodic foam's cell).
    pub periodic: bool,
}

/// Most bins a foam's region is split into: the page's lists stay a few texture rows a bin.
const MOST_FOAM_BINS: f64 = 32768.0;

/// Bins per axis splitting `size` into bins about `edge` wide, at most [`MOST_FOAM_BINS`].
fn foam_bins(size: Vec3, edge: f64) -> [usize; 3] {
    let volume = size[0] * size[1] * size[2];
    let edge = edge.max((volume / MOST_FOAM_BINS).cbrt());
    size.map(|s| ((s / edge).ceil() as usize).max(1))
}

/// Items listed per bin of `dims` (over a region of `size` from `phase`): each in the bins
/// whose centre `near` accepts (given the centre and the bins' half diagonal) among those its
/// box `bbox`, grown by the half diagonal, overlaps; as one list, bin after bin, and where each
/// bin's part of it starts (then the end).
fn binned<T: Copy>(
    dims: [usize; 3],
    size: Vec3,
    phase: Vec3,
    items: &[T],
    bbox: impl Fn(&T) -> Aabb,
    near: impl Fn(&T, Vec3, f64) -> bool,
) -> (Vec<T>, Vec<u32>) {
    let edge = [0, 1, 2].map(|a| size[a] / dims[a] as f64);
    let half = 0.5 * (edge[0] * edge[0] + edge[1] * edge[1] + edge[2] * edge[2]).sqrt();
    let bin = |c: [usize; 3]| (c[0] * dims[1] + c[1]) * dims[2] + c[2];
    let mut lists: Vec<Vec<T>> = vec![Vec::new(); dims[0] * dims[1] * dims[2]];
    for t in items {
        let g = bbox(t).grown(half);
        let range = |a: usize, x: f64| {
            (((x - phase[a]) / edge[a]).floor().max(0.0) as usize).min(dims[a] - 1)
        };
        if (0..3).any(|a| g.max[a] < phase[a] || g.min[a] > phase[a] + size[a]) {
            continue;
        }
        let lo = [0, 1, 2].map(|a| range(a, g.min[a]));
        let hi = [0, 1, 2].map(|a| range(a, g.max[a]));
        for i in lo[0]..=hi[0] {
            for j in lo[1]..=hi[1] {
                for k in lo[2]..=hi[2] {
                    let c = [i, j, k];
                    let centre = [0, 1, 2].map(|a| phase[a] + (c[a] as f64 + 0.5) * edge[a]);
                    if near(t, centre, half) {
                        lists[bin(c)].push(*t);
                    }
                }
            }
        }
    }
    let mut out = Vec::new();
    let mut starts = vec![0];
    for l in lists {
        out.extend(l);
        starts.push(out.len() as u32);
    }
    (out, starts)
}

impl Scene {
    /// The scene of a TPMS, strut or foam part.
    pub fn of(model: &Model) -> Scene {
        Scene::of_lattice(
            &model.lattice,
            model.level,
            model.reach(),
            model.bounds(),
            model.voxel,
            model.cell,
        )
    }

    /// The scene of a lattice at `level` (distances exact up to `reach`), clipped by `bounds`,
    /// meshed at `voxel` in cells whose shortest side is `cell`; a filled part adds its
    /// [`Fill`].
    pub fn of_lattice(
        lattice: &Lattice,
        level: f64,
        reach: f64,
        bounds: Aabb,
        voxel: f64,
        cell: f64,
    ) -> Scene {
        let mut scene = Scene {
            kind: "tpms",
            bounds: [bounds.min, bounds.max],
            voxel,
            cell,
            level,
            reach,
            tpms: None,
            struts: None,
            walls: None,
            fill: None,
        };
        match lattice {
            Lattice::Tpms(l) => {
                let l_axis = l.surface.lipschitz_per_axis();
                let lipschitz = (0..3)
                    .map(|a| (l_axis[a] / l.cell[a]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                let terms = l
                    .surface
                    .factors()
                    .into_iter()
                    .map(|(coef, f)| {
                        let [x, y, z] = f.map(|(k, t)| 3.0 * k as f64 + t as f64);
                        // The other labyrinth is the net of −F.
                        let sign = if l.structure == Structure::NetOther {
                            -1.0
                        } else {
                            1.0
                        };
                        [sign * coef, x, y, z]
                    })
                    .collect();
                scene.tpms = Some(Tpms {
                    terms,
                    sheet: l.structure == Structure::Sheet,
                    size: l.cell,
                    phase: l.phase,
                    lipschitz,
                });
            }
            Lattice::Struts(l) => {
                let max_radius = RADIUS_SPAN * l.radius;
                let wide = crate::lattice::strut::StrutLattice {
                    radius: max_radius,
                    ..l.clone()
                };
                let field = wide.field(reach);
                let all: Vec<[f64; 8]> = field
                    .struts()
                    .map(|([a, b], [fa, fb])| [a[0], a[1], a[2], fa, b[0], b[1], b[2], fb])
                    .collect();
                // Each bin's struts side by side, so that a sample reads its own bin's only.
                let mut struts = Vec::new();
                let mut bins = vec![0];
                for bin in field.bins() {
                    struts.extend(bin.iter().map(|&i| all[i as usize]));
                    bins.push(struts.len() as u32);
                }
                scene.kind = "struts";
                scene.struts = Some(Struts {
                    struts,
                    bins,
                    bins_per_axis: [crate::lattice::strut::field::BINS; 3],
                    blend: l.blend,
                    max_radius,
                    size: l.size,
                    phase: l.phase,
                });
            }
            Lattice::Foam(f) => match f.foam.structure {
                Foam::Net => {
                    scene.kind = "struts";
                    scene.struts = Some(foam_struts(f, reach, voxel, cell));
                }
                Foam::Sheet => {
                    scene.kind = "walls";
                    scene.walls = Some(foam_walls(f, reach, voxel, cell));
                }
            },
        }
        scene
    }
}

/// A random Voronoi net as one strut cell covering its box (grown by a voxel, so that no point
/// of the box wraps to the far side), its bins about half a spacing wide.
fn foam_struts(f: &FoamSolid, reach: f64, voxel: f64, spacing: f64) -> Struts {
    let max_radius = RADIUS_SPAN * f.level;
    let region = f.bounds.grown(voxel);
    let size = region.size();
    let centre = [0, 1, 2].map(|a| region.min[a] + 0.5 * size[a]);
    let dims = foam_bins(size, 0.5 * spacing);
    let far = max_radius + reach;
    let (struts, bins) = binned(
        dims,
        size,
        region.min,
        f.foam.segments(),
        |[a, b]| Aabb {
            min: [0, 1, 2].map(|k| a[k].min(b[k]) - far),
            max: [0, 1, 2].map(|k| a[k].max(b[k]) + far),
        },
        |&[a, b], c, half| crate::field::beams::segment_distance(c, a, b) <= far + half,
    );
    Struts {
        struts: struts
            .iter()
            .map(|[a, b]| {
                let (a, b) = (sub(*a, centre), sub(*b, centre));
                [a[0], a[1], a[2], 1.0, b[0], b[1], b[2], 1.0]
            })
            .collect(),
        bins,
        bins_per_axis: dims,
        blend: 0.0,
        max_radius,
        size,
        phase: region.min,
    }
}

/// A Voronoi sheet's seeds and pores by bin of the region drawn: a periodic foam's cell, or
/// the box grown by a voxel.
fn foam_walls(f: &FoamSolid, reach: f64, voxel: f64, spacing: f64) -> Walls {
    use rayon::prelude::*;
    let foam = &f.foam;
    let max_thickness = RADIUS_SPAN * f.level;
    let cap = 0.5 * max_thickness + reach;
    let (region, periodic) = match foam.period {
        Some(_) => (foam.bounds, true),
        None => (f.bounds.grown(voxel), false),
    };
    let size = region.size();
    let dims = foam_bins(size, 0.5 * spacing);
    let edge = [0, 1, 2].map(|a| size[a] / dims[a] as f64);
    let half = 0.5 * (edge[0] * edge[0] + edge[1] * edge[1] + edge[2] * edge[2]).sqrt();
    // A point `p` of a bin (centre `c`, half diagonal `h`) is nearest a seed within `a + 2h` of
    // `c` (`a`: the nearest seed's distance to `c`), and the part of its cell's boundary within
    // `cap` of it is bounded only by seeds within `|p − s₁| + 2·cap` of it: all within
    // `a + 4h + 2·cap` of `c`.
    let lists: Vec<Vec<u32>> = (0..dims[0] * dims[1] * dims[2])
        .into_par_iter()
        .map(|b| {
            let i = [
                b / (dims[1] * dims[2]),
                (b / dims[2]) % dims[1],
                b % dims[2],
            ];
            let c = [0, 1, 2].map(|a| region.min[a] + (i[a] as f64 + 0.5) * edge[a]);
            let a = foam.nearest_seed(c).1;
            foam.seeds_within(c, a + 4.0 * half + 2.0 * cap)
        })
        .collect();
    let mut seeds = Vec::new();
    let mut bins = vec![0];
    for l in lists {
        seeds.extend(l.into_iter().map(|i| {
            let q = sub(foam.seeds()[i as usize], region.min);
            [q[0], q[1], q[2], i as f64]
        }));
        bins.push(seeds.len() as u32);
    }
    let pores: Vec<((u32, u32), crate::lattice::voronoi::Pore)> =
        foam.pore_pairs().map(|(k, p)| (k, *p)).collect();
    let (pores, pore_bins) = binned(
        dims,
        size,
        region.min,
        &pores,
        |(_, p)| {
            let r = p.radius + cap;
            Aabb {
                min: p.centre.map(|x| x - r),
                max: p.centre.map(|x| x + r),
            }
        },
        |(_, p), c, half| dist(p.centre, c) <= p.radius + cap + half,
    );
    Walls {
        seeds,
        bins,
        bins_per_axis: dims,
        pores: pores
            .iter()
            .map(|((i, j), p)| {
                let c = sub(p.centre, region.min);
                let n = p.normal;
                [
                    c[0], c[1], c[2], p.radius, n[0], n[1], n[2], 0.0, *i as f64, *j as f64, 0.0,
                    0.0,
                ]
            })
            .collect(),
        pore_bins,
        max_thickness,
        size,
        phase: region.min,
        periodic,
    }
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dist(a: Vec3, b: Vec3) -> f64 {
    let d = sub(a, b);
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}
