//! Repairing a mesh file, as `latvox repair` does: check the input, repair it, write the result,
//! and give the verdict on the file as written and read back, as the next program will see it.

use super::{repair, RepairOptions, RepairReport};
use crate::check::deviation::{deviation, Deviation};
use crate::check::{check, read_file, CheckOptions, CheckReport, Defects};
use crate::error::{Error, Result};
use crate::geom::Mesh;
use crate::io::{Format, ReadOptions, Reading};
use crate::mesh::output::MeshFile;
use crate::progress::Progress;
use crate::verify::Verdict;
use std::path::Path;

/// Everything `latvox repair` reports.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FileRepairReport {
    /// The input file, as named.
    pub input: String,
    /// The output file, as named.
    pub output: String,
    /// The input's format.
    pub format: Format,
    /// What reading did to the input (faces skipped, polygons split, vertices merged).
    pub reading: Reading,
    /// The input's check (self-intersections are looked for on the result only).
    pub before: CheckReport,
    /// The defect classes found in the input, with their counts.
    pub defects_before: Defects,
    /// What repair changed.
    pub repair: RepairReport,
    /// Stored normals of the input that disagreed with the winding (the writers recompute them).
    pub normals_recomputed: u64,
    /// The check of the file as written and read back.
    pub after: CheckReport,
    /// The defect classes left in the written file, with their counts.
    pub defects_after: Defects,
    /// How far the result lies from the input, when repair moved geometry (a remesh, a union).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub deviation: Option<Deviation>,
    /// The verdict on `after` (in JSON, the one flag `valid_solid`).
    #[serde(
        rename = "valid_solid",
        serialize_with = "crate::verify::verdict::valid_solid"
    )]
    pub verdict: Verdict,
}

/// Whether `a` and `b` hold the same facets, corner by corner, at the same positions.
fn same_facets(a: &Mesh, b: &Mesh) -> bool {
    a.triangle_count() == b.triangle_count()
        && a.indices
            .iter()
            .zip(&b.indices)
            .all(|(&i, &j)| a.vertex(i) == b.vertex(j))
}

/// Reads `input`, checks it, repairs it, writes the result to `output` atomically and checks the
/// file as written. Vertices closer than `check_opts.tolerance` merge on reading the input. A
/// repair that leaves no facet is an error, and nothing is written.
pub fn repair_file(
    input: &Path,
    output: &MeshFile,
    check_opts: &CheckOptions,
    opts: &RepairOptions,
    progress: &Progress,
) -> Result<FileRepairReport> {
    let loaded = read_file(input, check_opts, progress)?;
    // CGAL's self-intersection test (the costliest check) runs once, on the result: repair does
    // not mend self-intersections, so the count before would only repeat it.
    let before = {
        let _s = progress.stage("checking the input");
        let opts = CheckOptions {
            self_intersections: false,
            ..*check_opts
        };
        check(&loaded.mesh, loaded.normals.as_deref(), &opts)?
    };
    let (mesh, changes) = repair(&loaded.mesh, opts, progress)?;
    if mesh.triangle_count() == 0 {
        return Err(Error::invalid(format!(
            "{}: nothing is left after repair (every facet was degenerate{}); no file written",
            input.display(),
            if opts.drop_open_shells {
                " or in an open shell"
            } else {
                ""
            }
        )));
    }
    {
        let _s = progress.stage("writing");
        output.save(&mesh)?;
    }
    // The verdict is on the file as written and read back, as the next program will see it
    // (STL, for one, welds vertices by position). A solid already searched for crossing facets
    // is not searched again when the file holds the same facets: welding only shares corners,
    // which can take intersections away, never add one.
    let after = {
        let _s = progress.stage("checking the written file");
        let written = crate::io::read(&output.path, &ReadOptions::default())?;
        let searched = check_opts.self_intersections
            && changes.solid.as_ref().is_some_and(|s| s.searched_free)
            && same_facets(&written.mesh, &mesh);
        let opts = CheckOptions {
            self_intersections: check_opts.self_intersections && !searched,
            ..*check_opts
        };
        let mut after = check(&written.mesh, written.normals.as_deref(), &opts)?;
        if searched {
            after.self_intersections = Some(0);
            after.valid_solid = after.verdict().is_valid_solid();
        }
        after
    };
    let moved = changes.remesh_voxel.is_some()
        || changes
            .solid
            .as_ref()
            .is_some_and(|s| s.intersecting_groups > 0);
    let deviation = if moved {
        let _s = progress.stage("measuring the deviation from the input");
        Some(deviation(&loaded.mesh, &mesh)?)
    } else {
        None
    };
    let normals_recomputed = before
        .normals
        .map(|n| n.reversed + n.inaccurate + n.unset)
        .unwrap_or(0);
    Ok(FileRepairReport {
        input: input.display().to_string(),
        output: output.path.display().to_string(),
        format: loaded.format,
        reading: loaded.reading(),
        defects_before: Defects::from(&before),
        before,
        repair: changes,
        normals_recomputed,
        defects_after: Defects::from(&after),
        deviation,
        verdict: after.verdict(),
        after,
    })
}
