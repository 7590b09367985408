//! What every part made through the pipeline reports: its density against the target, the mesh
//! written (counts, measures, bounds), CGAL's checks, the fragments the box cut loose, how it was
//! meshed (whole, copied from a template, in tiles), the time of each stage, and the verdict.
//! A capability's report adds what is its own (the surface and level, the cell and radius) and
//! flattens this one into it, so every report has the same keys for the same things.

use super::pieces::Fragments;
use super::pipeline::{
    Instancing, Made, Measured, MeshingStats, Route, Simplified, Tiling, Written, PROMISE,
};
use super::resolution::ResolutionMiss;
use crate::field::Aabb;
use crate::verify::cgal::Verification;
use crate::verify::Verdict;

/// Timings per stage, seconds.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct Timings {
    /// The capability's model of its cell (the unit cell's sample table and calibration, the
    /// strut radius model).
    pub calibrate: f64,
    /// Sampling the field into OpenVDB grids.
    pub sample: f64,
    /// OpenVDB's meshing.
    pub mesh: f64,
    /// Snapping the vertices onto the surface and box.
    pub snap: f64,
    /// Simplifying the mesh within a tolerance (meshing it on finer voxels first included).
    pub simplify: f64,
    /// CGAL's checks.
    pub verify: f64,
    /// Writing the part.
    pub write: f64,
    /// The whole job.
    pub total: f64,
}

/// How the part's level was found: the part (or a template of its cells) meshed at each level
/// tried, and the volume fraction measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct LevelSearch {
    /// What was measured: `part` (the whole part), `template` (a template of its cells, which
    /// gives the part's volume) or `tiles` (the part meshed tile by tile, not kept).
    pub measured_on: &'static str,
    /// `[level, volume fraction]` of each meshing, in order.
    pub tried: Vec<[f64; 2]>,
    /// Resolutions tried before the one used, with the closest fraction each could give.
    pub coarser: Vec<ResolutionMiss>,
}

impl LevelSearch {
    /// The search that found `best` on `route`, after `tried`, at the resolution after
    /// `coarser`.
    pub fn new(
        best: &Measured,
        route: Route,
        tried: &[(f64, f64)],
        coarser: Vec<ResolutionMiss>,
    ) -> LevelSearch {
        LevelSearch {
            measured_on: match (&best.made, route) {
                (Made::Whole(_), _) => "part",
                (_, Route::Tiled(_, None)) => "tiles",
                _ => "template",
            },
            tried: tried.iter().map(|&(t, f)| [t, f]).collect(),
            coarser,
        }
    }
}

/// The part as written.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PartReport {
    /// The volume fraction asked for (`null` when the part was made to a size instead, such as
    /// a strut radius).
    pub target_density: Option<f64>,
    /// Volume fraction of the written mesh: its enclosed volume (divergence theorem over the
    /// triangles exactly as written) over the box volume.
    pub achieved_density: f64,
    /// `achieved_density − target_density`.
    pub density_error: Option<f64>,
    /// Whether the written mesh is within 0.002 of the target density.
    pub density_met: Option<bool>,
    /// The part's box, mm.
    #[serde(rename = "box")]
    pub bounds: Aabb,
    /// Triangles written.
    pub triangles: u64,
    /// Vertices of the part.
    pub vertices: u64,
    /// Surface area of the written mesh, mm².
    pub area: f64,
    /// Volume enclosed by the written mesh, mm³.
    pub volume: Option<f64>,
    /// Bounding box of the written mesh, mm (`null` when empty).
    pub bounding_box: Option<Aabb>,
    /// CGAL's checks: on the written mesh, or on the template when `instancing` is set.
    pub checks: Verification,
    /// Pieces of the lattice the box cut loose: removed (unless kept with `keep_fragments`).
    pub fragments: Fragments,
    /// Whether what was written is one piece.
    pub one_piece: Option<bool>,
    /// Set when the part was copied from a template.
    pub instancing: Option<Instancing>,
    /// Set when the part was meshed in tiles.
    pub tiling: Option<Tiling>,
    /// Set when the mesh was simplified within a tolerance: the tolerance, the largest
    /// deviation measured on the written mesh, the triangles before and after.
    pub simplified: Option<Simplified>,
    /// Meshing statistics over every meshing of the job.
    pub meshing: MeshingStats,
    /// Wall time of each stage.
    pub timings: Timings,
    /// Warnings, one sentence each (islands, raised resolution, fragments, …).
    pub warnings: Vec<String>,
    /// The output file, when the command line wrote one.
    pub output: Option<String>,
}

impl PartReport {
    /// [`PartReport::new`] for a part written after a resolution search: the search's warning
    /// (the resolution raised) first, the total time since `start`.
    #[allow(clippy::too_many_arguments)]
    pub fn after_search(
        bounds: Aabb,
        target: Option<f64>,
        route: Route,
        written: Written,
        search: MeshingStats,
        calibrate: f64,
        raised: Option<String>,
        start: std::time::Instant,
    ) -> PartReport {
        let timings = Timings {
            calibrate,
            ..Timings::default()
        };
        let mut part = PartReport::new(bounds, target, route, written, search, timings);
        let mut warnings: Vec<String> = raised.into_iter().collect();
        warnings.append(&mut part.warnings);
        part.warnings = warnings;
        part.timings.total = start.elapsed().as_secs_f64();
        part
    }

    /// The report of the part `written` on `route` in `bounds`, made to `target` (if any):
    /// `search` holds the meshings that found its level, `timings` the capability's own
    /// (calibration, total) — the meshing's are filled in here, and the warnings of the written
    /// mesh added.
    pub fn new(
        bounds: Aabb,
        target: Option<f64>,
        route: Route,
        written: Written,
        search: MeshingStats,
        timings: Timings,
    ) -> PartReport {
        // The meshings of the search are part of the work (the whole route's last one is the
        // part's own mesh).
        let mut meshing = search;
        if !matches!(route, Route::Whole(None)) {
            meshing.add(&written.meshing);
        }
        let measures = written.measures;
        let achieved = measures.volume / bounds.volume();
        let one_piece = Some(written.fragments.count == 0 || written.fragments.removed);
        let mut report = PartReport {
            target_density: target,
            achieved_density: achieved,
            density_error: target.map(|t| achieved - t),
            density_met: target.map(|t| (achieved - t).abs() <= PROMISE),
            bounds,
            triangles: measures.triangles,
            vertices: written.vertices,
            area: measures.area,
            volume: Some(measures.volume),
            bounding_box: (measures.triangles > 0).then_some(measures.bounds),
            checks: written.checks,
            fragments: written.fragments,
            one_piece,
            instancing: written.instancing,
            tiling: written.tiling,
            simplified: written.simplified,
            timings: Timings {
                sample: meshing.sample_seconds,
                mesh: meshing.mesh_seconds,
                snap: meshing.snap_seconds,
                simplify: written.simplified.map_or(0.0, |s| s.stats.seconds),
                verify: written.verify_seconds,
                write: written.write_seconds,
                ..timings
            },
            meshing,
            warnings: Vec::new(),
            output: None,
        };
        report.warnings = report.written_warnings();
        report
    }

    /// Measures the density against another base than the box (a filled part: the lattice's
    /// share of the region it fills): `achieved` against `target`, the warnings redone.
    pub fn density_against(&mut self, target: f64, achieved: f64) {
        self.target_density = Some(target);
        self.achieved_density = achieved;
        self.density_error = Some(achieved - target);
        self.density_met = Some((achieved - target).abs() <= PROMISE);
        self.warnings = self.written_warnings();
    }

    /// What the written mesh says that the user should hear: a missed density (a bug), a
    /// failed CGAL check, fragments cut loose by the box.
    fn written_warnings(&self) -> Vec<String> {
        let mut warnings = Vec::new();
        if let (Some(target), Some(false)) = (self.target_density, self.density_met) {
            warnings.push(format!(
                "the written mesh's density {:.4} misses the target {target} by more than {PROMISE}: please report this",
                self.achieved_density
            ));
        }
        if !self.checks.verdict().is_valid_solid() {
            warnings.push(format!(
                "the mesh is not a valid closed, outward, self-intersection-free solid (checked by {})",
                self.checks.checked_by
            ));
        }
        if let Some(s) = self.simplified.filter(|s| s.deviation > s.stats.tolerance) {
            warnings.push(format!(
                "the mesh strays {:.4} mm from the exact surface, more than the tolerance {} mm: the uniform mesh already did at the box's cut edges or where members meet (a finer --resolution brings it within)",
                s.deviation, s.stats.tolerance
            ));
        }
        let fragments = &self.fragments;
        if fragments.count > 0 {
            warnings.push(format!(
                "{} fragment{} cut loose by the box or the part's surface ({:.3} mm³) {}",
                fragments.count,
                if fragments.count == 1 { "" } else { "s" },
                fragments.volume,
                if fragments.removed {
                    "removed"
                } else {
                    "kept: they are not joined to the part"
                }
            ));
        }
        let voids = match fragments.cavities {
            0 => None,
            1 => Some("1 void".to_string()),
            n => Some(format!("{n} voids")),
        };
        if let Some(voids) = voids {
            warnings.push(format!(
                "the part encloses {voids} ({:.3} mm³) that powder or resin cannot leave (`latvox fill --drain MM` opens escape holes through a skin)",
                fragments.cavity_volume,
            ));
        }
        warnings
    }

    /// The part's verdict: CGAL's checks (on the part, its template or its tiles), one piece
    /// (unless fragments were kept on purpose), and the density when one was asked for.
    pub fn verdict(&self) -> Verdict {
        let kept_on_purpose = !self.fragments.removed && self.fragments.count > 0;
        Verdict {
            one_piece: self.one_piece.filter(|_| !kept_on_purpose),
            density_met: self.density_met,
            ..self.checks.verdict()
        }
    }
}
