//! An FGM job: geometry (a scan or a mesh) → signed distance grid → the part's mesh, checked →
//! the distance to the material features on every voxel of the part → material fractions; and
//! the files made from them (a `.vdb` of named grids, a mesh with its composition per vertex,
//! voxel-print PNG stacks, a preview).

use super::cloud::Cloud;
use super::geometry::{ScanSdf, Sign};
use super::material::{Composition, Features};
use crate::error::{Error, Result};
use crate::field::{Aabb, Vec3};
use crate::geom::Mesh;
use crate::grid::{Grid, GridSpec};
use crate::io::points::PointCloud;
use crate::mesh::extract::KeyedMesh;
use crate::mesh::pipeline::HALF_WIDTH;
use crate::mesh::simplify::Simplified;
use crate::progress::Progress;
use crate::repair::simplify_to_mesh;
use crate::verify::cgal::Verification;
use crate::verify::{verify, Verify};
use rayon::prelude::*;
use std::time::Instant;

/// Where the part's geometry comes from.
pub enum Geometry {
    /// A scanned point cloud (normals optional).
    Points(PointCloud),
    /// A closed mesh.
    Mesh(Mesh),
    /// A plane contour: points at `z = 0` ([`FgmJob::run_plane`]).
    Contour(PointCloud),
}

/// What to make.
pub struct FgmJob {
    /// The geometry.
    pub geometry: Geometry,
    /// Its file's name, for reports.
    pub input_name: String,
    /// Voxel edge, mm.
    pub voxel: f64,
    /// How a scan's inside is told from its outside.
    pub sign: Sign,
    /// What the composition is graded from.
    pub features: Features,
    /// The materials and their laws.
    pub composition: Composition,
    /// The distance at which a power law reaches 1; by default the largest over the part.
    pub dmax: Option<f64>,
    /// How the part's mesh is verified.
    pub verify: Verify,
    /// Simplify the part's mesh within this distance of the part's surface, mm (`None`: the
    /// uniform mesh).
    pub tolerance: Option<f64>,
}

/// What the geometry stage found.
#[derive(Debug, Clone, serde::Serialize)]
pub struct GeometryReport {
    /// `points`, `mesh` or `contour`.
    pub source: &'static str,
    /// Points read (a scan).
    pub points: Option<usize>,
    /// Median spacing of the points, mm (a scan).
    pub point_spacing: Option<f64>,
    /// Whether normals were estimated (the file had none).
    pub normals_estimated: Option<bool>,
    /// Whether the normals had to be flipped to point outward.
    pub normals_flipped: Option<bool>,
    /// How the inside was told (a scan).
    pub sign: Option<Sign>,
    /// Voxel edge, mm.
    pub voxel: f64,
    /// Active voxels of the signed distance grid (its narrow band).
    pub band_voxels: u64,
    /// Memory of the signed distance grid, bytes (OpenVDB's count).
    pub grid_bytes: u64,
}

/// An FGM part: its grids, its mesh and what was measured.
pub struct Fgm {
    /// The signed distance (narrow band).
    pub sdf: Grid,
    /// The part's surface.
    pub mesh: Mesh,
    /// The materials.
    pub composition: Composition,
    /// Blocks of the part's voxels (first samples of the sdf's spec): its band and inside.
    pub blocks: Vec<[i64; 3]>,
    /// The distance at which a power law reaches 1, mm.
    pub dmax: f64,
    /// The distance to the features at every voxel of `blocks`, NaN outside the part beyond
    /// the band (read back, block by block, wherever the fractions are needed).
    pub distance_grid: Grid,
    /// The geometry stage's report.
    pub geometry: GeometryReport,
    /// The mesh's verification.
    pub checks: Verification,
    /// Set when the mesh was simplified within the job's tolerance.
    pub simplified: Option<Simplified>,
    /// Seconds per stage.
    pub timings: Vec<(&'static str, f64)>,
}

impl FgmJob {
    /// Runs the job up to the part's grids and mesh (the files are written from the result).
    pub fn run(&self, progress: &Progress) -> Result<Fgm> {
        if !(self.voxel > 0.0 && self.voxel.is_finite()) {
            return Err(Error::invalid("--voxel must be a positive length in mm"));
        }
        let mut timings = Vec::new();
        let t = Instant::now();
        let stage = progress.stage("signed distance");
        let (sdf, geometry) = match &self.geometry {
            Geometry::Points(pc) => {
                let cloud = Cloud::new(pc.clone())?;
                let b = cloud.bounds();
                let pad = 2.0 * self.voxel + 3.0 * cloud.median_spacing;
                let bounds = Aabb {
                    min: b.min.map(|x| x - pad),
                    max: b.max.map(|x| x + pad),
                };
                check_size(&bounds, self.voxel)?;
                let spec = GridSpec::covering(&bounds, self.voxel, HALF_WIDTH);
                let field = ScanSdf::new(&cloud, spec, self.sign);
                let grid = Grid::sample_signed(&field, spec, &|b| field.inside_block(b))?;
                let report = GeometryReport {
                    source: "points",
                    points: Some(cloud.points.len()),
                    point_spacing: Some(cloud.median_spacing),
                    normals_estimated: Some(cloud.normals_estimated),
                    normals_flipped: Some(cloud.normals_flipped),
                    sign: Some(self.sign),
                    voxel: self.voxel,
                    band_voxels: grid.active_voxels(),
                    grid_bytes: grid.memory_bytes(),
                };
                (grid, report)
            }
            Geometry::Contour(_) => {
                return Err(Error::invalid(
                    "a plane contour makes an image, not a solid",
                ))
            }
            Geometry::Mesh(mesh) => {
                let b = mesh
                    .bounds()
                    .ok_or_else(|| Error::invalid("the mesh has no triangles"))?;
                check_size(&b, self.voxel)?;
                let grid = Grid::from_mesh(mesh, self.voxel, HALF_WIDTH)?;
                let report = GeometryReport {
                    source: "mesh",
                    points: None,
                    point_spacing: None,
                    normals_estimated: None,
                    normals_flipped: None,
                    sign: None,
                    voxel: self.voxel,
                    band_voxels: grid.active_voxels(),
                    grid_bytes: grid.memory_bytes(),
                };
                (grid, report)
            }
        };
        drop(stage);
        timings.push(("signed distance", t.elapsed().as_secs_f64()));

        let t = Instant::now();
        let stage = progress.stage("mesh");
        let mesh = match &self.geometry {
            // Sampled here, its values kept off zero: every vertex keyed to its voxel.
            Geometry::Points(_) => {
                let mut keyed = KeyedMesh::extract(&sdf)?;
                keyed.triangulate();
                keyed.into_mesh()
            }
            // OpenVDB's own distance, which may be 0 on a sample: its own mesher.
            Geometry::Mesh(_) | Geometry::Contour(_) => sdf.to_mesh(0.0)?,
        };
        if mesh.triangle_count() == 0 {
            return Err(Error::invalid(
                "the geometry encloses nothing at this voxel size (a finer --voxel, or a closed scan)",
            ));
        }
        drop(stage);
        let (mesh, simplified) = match self.tolerance {
            Some(tolerance) => {
                let _s = progress.stage("simplifying");
                // A mesh is the part's surface itself; a scan's points are noisy samples of
                // one, and the part is the surface meshed from their distance field.
                let surface = match &self.geometry {
                    Geometry::Mesh(input) => input,
                    _ => &mesh,
                };
                let (m, s) = simplify_to_mesh(&mesh, surface, self.voxel, tolerance);
                (m, Some(s))
            }
            None => (mesh, None),
        };
        let checks = verify(&mesh, self.verify, progress)?;
        timings.push(("mesh and verify", t.elapsed().as_secs_f64()));

        let t = Instant::now();
        let stage = progress.stage("material distance");
        let skin = if self.features.uses_skin() {
            let b = sdf.spec.dims.iter().copied().max().unwrap_or(1) as f64;
            Some(Grid::distance_to_mesh(
                &mesh,
                self.voxel,
                HALF_WIDTH + 1.0,
                b + 8.0,
            )?)
        } else {
            None
        };
        let mut blocks = sdf.leaf_blocks();
        blocks.extend(sdf.interior_blocks());
        // Filled in place, a block of 512 at a time; the largest distance inside the part.
        let mut distance = vec![0f32; 512 * blocks.len()];
        let band = (HALF_WIDTH * sdf.spec.voxel) as f32;
        let largest = distance
            .par_chunks_mut(512)
            .zip(blocks.par_iter())
            .map_init(
                || {
                    (
                        Vec::with_capacity(3 * 512),
                        vec![0f32; 512],
                        vec![0f32; 512],
                    )
                },
                |(pts, s, sk), (d, b)| {
                    block_points(&sdf.spec, *b, pts);
                    sdf.probe(pts, s);
                    if let Some(g) = &skin {
                        g.probe(pts, sk);
                    }
                    let mut largest = 0.0f64;
                    for v in 0..512 {
                        d[v] = if s[v] >= band {
                            f32::NAN
                        } else {
                            let p = [pts[3 * v], pts[3 * v + 1], pts[3 * v + 2]];
                            self.features.distance(p, sk[v].abs() as f64) as f32
                        };
                        if s[v] <= 0.0 {
                            largest = largest.max(d[v] as f64);
                        }
                    }
                    largest
                },
            )
            .reduce(|| 0.0, f64::max);
        drop(skin);
        let dmax = choose_dmax(self.dmax, largest)?;
        self.composition.check(dmax)?;
        let distance_grid = sdf.values_like(&blocks, &distance, 0.0, false)?;
        drop(stage);
        timings.push(("material distance", t.elapsed().as_secs_f64()));
        Ok(Fgm {
            sdf,
            mesh,
            composition: self.composition.clone(),
            blocks,
            dmax,
            distance_grid,
            geometry,
            checks,
            simplified,
            timings,
        })
    }
}

/// The distance at which a power law reaches 1: `given`, or the `largest` distance in the part.
pub(crate) fn choose_dmax(given: Option<f64>, largest: f64) -> Result<f64> {
    match given {
        Some(d) if d > 0.0 && d.is_finite() => Ok(d),
        Some(d) => Err(Error::invalid(format!(
            "--dmax {d} must be a positive length in mm"
        ))),
        None if largest > 0.0 => Ok(largest),
        None => Err(Error::invalid(
            "the distance to the features is 0 throughout the part",
        )),
    }
}

/// Refuses a grid too large to be meant (a voxel in micrometres on a part in metres).
fn check_size(b: &Aabb, voxel: f64) -> Result<()> {
    let s = b.size();
    let n: f64 = s.iter().map(|x| (x / voxel).max(1.0)).product();
    if n > 1e12 {
        return Err(Error::invalid(format!(
            "--voxel {voxel} mm on a part of {:.1} × {:.1} × {:.1} mm makes {n:.1e} voxels; choose a coarser voxel",
            s[0], s[1], s[2]
        )));
    }
    Ok(())
}

impl Fgm {
    /// The centres, signed distances and feature distances of block `b`'s voxels (OpenVDB's
    /// order), read back from the grids.
    fn block_values(&self, b: [i64; 3], pts: &mut Vec<f64>, s: &mut [f32], d: &mut [f32]) {
        block_points(&self.sdf.spec, b, pts);
        self.sdf.probe(pts, s);
        self.distance_grid.probe(pts, d);
    }

    /// The fractions of material `k` at every voxel of `blocks`, NaN outside the part.
    pub fn fraction_values(&self, k: usize) -> Vec<f32> {
        let n = self.composition.materials.len();
        let mut out = vec![0f32; 512 * self.blocks.len()];
        out.par_chunks_mut(512)
            .zip(self.blocks.par_iter())
            .for_each_init(
                || (Vec::new(), vec![0f32; 512], vec![0f32; 512], vec![0.0; n]),
                |(pts, s, d, f), (o, b)| {
                    self.block_values(*b, pts, s, d);
                    for v in 0..512 {
                        o[v] = if s[v] <= 0.0 {
                            self.composition.fractions(d[v] as f64, self.dmax, f);
                            f[k] as f32
                        } else {
                            f32::NAN
                        };
                    }
                },
            );
        out
    }

    /// The fractions at distance `d`, into `out`.
    pub fn fractions_at(&self, d: f64, out: &mut [f64]) {
        self.composition.fractions(d, self.dmax, out)
    }

    /// The volume share of each material in the part (voxel count weighted).
    pub fn shares(&self) -> Vec<f64> {
        let n = self.composition.materials.len();
        // Per block, then added in the blocks' order: the shares do not change with scheduling.
        let per_block: Vec<(Vec<f64>, usize)> = self
            .blocks
            .par_iter()
            .map_init(
                || (Vec::new(), vec![0f32; 512], vec![0f32; 512], vec![0.0; n]),
                |(pts, s, d, f), b| {
                    self.block_values(*b, pts, s, d);
                    let mut sum = vec![0.0; n];
                    let mut count = 0usize;
                    for v in (0..512).filter(|&v| s[v] <= 0.0) {
                        self.fractions_at(d[v] as f64, f);
                        for k in 0..n {
                            sum[k] += f[k];
                        }
                        count += 1;
                    }
                    (sum, count)
                },
            )
            .collect();
        let (mut sum, mut count) = (vec![0.0; n], 0);
        for (s, c) in per_block {
            for k in 0..n {
                sum[k] += s[k];
            }
            count += c;
        }
        sum.iter().map(|s| s / count.max(1) as f64).collect()
    }

    /// Writes the `.vdb`: `sdf` (the narrow-band level set), `distance` (to the features, on
    /// the part's voxels and its band) and one fog grid per material (its fraction, 0 outside).
    pub fn write_vdb(&self, path: &std::path::Path) -> Result<()> {
        let mut grids = Vec::new();
        for k in 0..self.composition.materials.len() {
            grids.push(
                self.sdf
                    .values_like(&self.blocks, &self.fraction_values(k), 0.0, true)?,
            );
        }
        let mut named: Vec<(&str, &Grid)> =
            vec![("sdf", &self.sdf), ("distance", &self.distance_grid)];
        for (name, g) in self.composition.materials.iter().zip(&grids) {
            named.push((name, g));
        }
        let tmp = crate::io::atomic::temp_beside(path)?;
        crate::grid::write_vdb_grids(tmp.path(), &named)?;
        tmp.persist(path).map_err(|e| Error::io(path, e.error))?;
        Ok(())
    }

    /// The fractions at each of the mesh's vertices (they lie on the skin: distance 0 to it).
    pub fn vertex_fractions(&self, features: &Features) -> Vec<Vec<f64>> {
        let n = self.composition.materials.len();
        self.mesh
            .positions
            .par_chunks_exact(3)
            .map(|p| {
                let p: Vec3 = [p[0] as f64, p[1] as f64, p[2] as f64];
                let mut f = vec![0.0; n];
                self.fractions_at(features.distance(p, 0.0), &mut f);
                f
            })
            .collect()
    }
}

/// The centres of block `b`'s 512 voxels on `spec` (x slowest, OpenVDB's order), into `pts`.
fn block_points(spec: &GridSpec, b: [i64; 3], pts: &mut Vec<f64>) {
    pts.clear();
    for i in 0..8 {
        for j in 0..8 {
            for k in 0..8 {
                pts.extend(spec.point([b[0] + i, b[1] + j, b[2] + k]));
            }
        }
    }
}

/// The colour of a composition: the palette colours mixed by the fractions.
pub fn mix(fractions: &[f64], palette: &[[u8; 3]]) -> [u8; 3] {
    let mut c = [0.0; 3];
    for (f, p) in fractions.iter().zip(palette) {
        for a in 0..3 {
            c[a] += f.clamp(0.0, 1.0) * p[a] as f64;
        }
    }
    c.map(|x| x.round().clamp(0.0, 255.0) as u8)
}
