//! Checking a mesh file, as `latvox check` does: read it, run latvox's own checks and CGAL's side
//! by side, and join their findings into one [`Verdict`] and one report.

use super::{check, CheckOptions, CheckReport, Verdict};
use crate::error::Result;
use crate::geom::EdgeStats;
use crate::io::{Format, Loaded, ReadOptions, Reading};
use crate::progress::Progress;
use crate::verify::cgal::Verification;
use std::path::Path;

/// The defect classes found, with their counts, in the order [`CheckReport::defects`] gives
/// them; a JSON object of counts by name.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Defects(pub Vec<(&'static str, u64)>);

impl From<&CheckReport> for Defects {
    fn from(r: &CheckReport) -> Defects {
        Defects(r.defects())
    }
}

impl serde::Serialize for Defects {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.collect_map(self.0.iter().map(|(k, n)| (k, n)))
    }
}

/// Everything `latvox check` reports on a file.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FileCheckReport {
    /// The file, as named.
    pub file: String,
    /// The file's format, as read.
    pub format: Format,
    /// latvox's and CGAL's findings together (in JSON, the one flag `valid_solid`).
    #[serde(
        rename = "valid_solid",
        serialize_with = "crate::verify::verdict::valid_solid"
    )]
    pub verdict: Verdict,
    /// Triangles after reading (polygons split).
    pub triangles: u64,
    /// Vertices after welding.
    pub vertices: u64,
    /// The edge counts of the check, in the shape of [`crate::geom::Mesh::edge_stats`].
    pub edges: EdgeStats,
    /// What reading did to the file (faces skipped, polygons split, vertices merged).
    pub reading: Reading,
    /// latvox's own checks.
    pub check: CheckReport,
    /// The defect classes found, with their counts.
    pub defects: Defects,
    /// CGAL's checks: closedness, orientation and volume by CGAL (a second opinion on latvox's
    /// counts); the self-intersection finding is the one latvox's exact search made.
    pub cgal: Verification,
}

/// Reads the mesh file `path` to be checked: vertices closer than `opts.tolerance` merge, as
/// they count as lying on an edge when checking; beam lattices are meshed into solids (see
/// [`crate::mesh::part`]).
pub fn read_file(path: &Path, opts: &CheckOptions, progress: &Progress) -> Result<Loaded> {
    let _s = progress.stage("reading");
    let read = ReadOptions {
        weld_tolerance: opts.tolerance,
        beam_voxel: opts.beam_voxel,
    };
    crate::mesh::part::read(path, &read)
}

/// Reads and checks the mesh file `path` (see [`read_file`]).
pub fn check_file(
    path: &Path,
    opts: &CheckOptions,
    progress: &Progress,
) -> Result<FileCheckReport> {
    let loaded = read_file(path, opts, progress)?;
    let mesh = &loaded.mesh;
    // CGAL's own checks (building a mesh of its own, one facet at a time) run alongside ours.
    let (report, cgal) = {
        let _s = progress.stage("checking");
        rayon::join(
            || check(mesh, loaded.normals.as_deref(), opts),
            || crate::verify::cgal::verify(mesh, false),
        )
    };
    let (report, mut cgal) = (report?, cgal?);
    // The check above already searched for self-intersections (on the facets that are neither
    // degenerate nor duplicate, with CGAL's exact triangle tests); it is not run twice.
    cgal.self_intersection_checked = report.self_intersections.is_some();
    cgal.self_intersecting = report.self_intersections.unwrap_or(0) > 0;
    Ok(FileCheckReport {
        file: path.display().to_string(),
        format: loaded.format,
        verdict: report.verdict().and(cgal.verdict()),
        triangles: mesh.triangle_count() as u64,
        vertices: mesh.vertex_count() as u64,
        edges: EdgeStats {
            edges: report.edges,
            boundary: report.boundary_edges,
            non_manifold: report.non_manifold_edges,
            misoriented: report.inconsistent_edges,
        },
        reading: loaded.reading(),
        defects: Defects::from(&report),
        check: report,
        cgal,
    })
}
