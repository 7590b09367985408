//! A part as the editor's shader draws it: the numbers its uniforms and strut texture take.

use crate::field::{Aabb, Vec3};
use crate::geom::bvh::Bvh;
use crate::lattice::tpms::Structure;
use crate::render::{Model, Periodic};
use serde::Serialize;

/// How far above the part's radius the page's radius control reaches: the strut list is built
/// for that radius, so that every radius up to it draws every strut that reaches a cell.
pub const RADIUS_SPAN: f64 = 2.0;

/// What the page draws.
#[derive(Debug, Clone, Serialize)]
pub struct Scene {
    /// `"tpms"` or `"struts"`.
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
    /// A strut lattice's augmented cell.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub struts: Option<Struts>,
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
/// reach of it), in the cell's centred coordinates, listed per bin of the cell.
#[derive(Debug, Clone, Serialize)]
pub struct Struts {
    /// Per strut of each bin in turn: `a`, its radius factor, `b`, its radius factor.
    pub struts: Vec<[f64; 8]>,
    /// Where each bin's struts start in `struts` (bin `(i·n + j)·n + k`), and their end.
    pub bins: Vec<u32>,
    /// Bins per axis, `n`: they split the cell into equal parts.
    pub bins_per_axis: usize,
    /// Joint blend radius, mm.
    pub blend: f64,
    /// The largest radius the list holds every strut for, mm.
    pub max_radius: f64,
    /// Cell size per axis, mm.
    pub size: Vec3,
    /// A cell's lower corner, mm.
    pub phase: Vec3,
}

impl Scene {
    /// The scene of a TPMS or strut part.
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
        lattice: &Periodic,
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
            fill: None,
        };
        match lattice {
            Periodic::Tpms(l) => {
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
            Periodic::Struts(l) => {
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
                    bins_per_axis: crate::lattice::strut::field::BINS,
                    blend: l.blend,
                    max_radius,
                    size: l.size,
                    phase: l.phase,
                });
            }
        }
        scene
    }
}
