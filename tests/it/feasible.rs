//! The feasible ranges latvox refuses densities by are right at both ends: the tabulated ranges
//! (`calibrate::PERCOLATION`, constants in the source) are tested here just inside and just
//! outside each end by percolation of the sampled unit cell (union-find over a periodic 2×2×2
//! block), and the command line refuses
//! a density just outside the solid's range with the range in its one-line message.

use latvox::tpms::calibrate::{percolates, PERCOLATION};
use std::process::Command;

/// How far inside / outside an end the test looks, in volume fraction.
const STEP: f64 = 0.004;

/// The main tier tests the ends above 0.12 (on 64³ samples per cell); the long tier, the thin-strut
/// limits below it (on 128³).
#[test]
fn every_range_end_above_0_12_is_where_percolation_changes() {
    range_ends(false);
}

#[test]
#[ignore = "long: the thin-strut limits, on 128³ samples per cell"]
fn every_thin_strut_limit_is_where_percolation_changes() {
    range_ends(true);
}

fn range_ends(all: bool) {
    let mut failures = Vec::new();
    let mut ends = 0;
    for (surface, structure, solid, void) in PERCOLATION {
        for (range, is_void) in [(solid, false), (void, true)] {
            // An end at 0 or 1 is the end of the fraction range itself, not a percolation limit.
            for (end, inward) in [(range.min, 1.0), (range.max, -1.0)] {
                // The main tier's ends are above 0.12, the long tier's below.
                if end <= 0.0 || end >= 1.0 || all != (end < 0.12) {
                    continue;
                }
                ends += 1;
                let inside = end + inward * STEP;
                let outside = end - inward * STEP;
                // Ends below 0.12 are thin-strut limits, resolved at 128 samples per cell.
                let n = if end < 0.12 { 128 } else { 64 };
                let (a, b) = (
                    percolates(surface, structure, inside, n, is_void),
                    percolates(surface, structure, outside, n, is_void),
                );
                let what = if is_void { "void" } else { "solid" };
                eprintln!(
                    "{:8} {:6} {what:5} end {end:.4}: connected at {inside:.4} {a}, at {outside:.4} {b}",
                    surface.name(),
                    structure.name()
                );
                if !a || b {
                    failures.push(format!(
                        "{surface:?} {structure:?} {what} end {end}: connected {a} at {inside}, {b} at {outside}"
                    ));
                }
            }
        }
    }
    assert!(ends >= if all { 4 } else { 8 }, "only {ends} ends tested");
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn a_density_outside_the_solid_range_is_refused_with_the_range() {
    let dir = tempfile::tempdir().unwrap();
    for (surface, structure, solid, _) in PERCOLATION {
        for (end, outward) in [(solid.min, -1.0), (solid.max, 1.0)] {
            if end <= 0.0 || end >= 1.0 {
                continue;
            }
            let density = format!("{:.4}", end + outward * STEP);
            let out = dir.path().join("x.stl");
            let o = Command::new(env!("CARGO_BIN_EXE_latvox"))
                .args(["tpms", "--type", surface.name(), "--structure"])
                .args([
                    structure.name(),
                    "--density",
                    &density,
                    "--cells",
                    "1",
                    "-o",
                ])
                .arg(&out)
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(
                o.status.code(),
                Some(2),
                "{surface:?} {structure:?} {density}: {err}"
            );
            let range = format!("{:.3} to {:.3}", solid.min, solid.max);
            assert!(err.contains(&range), "message lacks {range}: {err}");
            assert_eq!(err.trim_end().lines().count(), 1, "{err}");
            assert!(!out.exists());
        }
    }
}

/// A library user matches on what went wrong and reads its data: an infeasible density carries
/// the range the lattice holds together in, a setting out of its range names the setting, and
/// voxels too coarse for fixed voxels carry the resolution that works.
#[test]
fn refusals_are_typed_errors_that_carry_their_data() {
    use latvox::tpms::{Domain, Structure, Surface, TpmsJob};
    use latvox::Error;
    let job = |density: f64, resolution: u32, auto_resolution: bool| TpmsJob {
        surface: Surface::P,
        structure: Structure::Net,
        density,
        domain: Domain::from_cells([2; 3], [5.0; 3], [0.0; 3]).unwrap(),
        resolution,
        adaptivity: 0.0,
        tolerance: None,
        allow_islands: false,
        auto_resolution,
        verify: latvox::verify::Verify::Fast,
        instancing: true,
        tile: None,
        memory: None,
        keep_fragments: false,
        grading: None,
        blend: None,
        cell_map: None,
    };
    let run = |j: TpmsJob| j.run(&latvox::progress::Progress::hidden()).map(|_| ());
    let range = latvox::tpms::calibrate::feasible(Surface::P, Structure::Net);
    match run(job(range.min - 0.02, 24, true)) {
        Err(Error::Infeasible {
            setting,
            value,
            min,
            max,
            message,
        }) => {
            assert_eq!(setting, "density");
            assert_eq!(value, range.min - 0.02);
            assert_eq!((min, max), (range.min, range.max));
            assert!(message.contains(&format!("{:.3}", range.min)), "{message}");
        }
        other => panic!("an infeasible density: {other:?}"),
    }
    match run(job(1.5, 24, true)) {
        Err(e @ Error::Setting { .. }) => {
            let Error::Setting { setting, .. } = &e else {
                unreachable!()
            };
            assert_eq!(setting, "density");
            assert_eq!(e.exit_code(), 2);
        }
        other => panic!("a density out of (0, 1): {other:?}"),
    }
    // A thin sheet on fixed, coarse voxels: refused with the resolution that works, which works.
    let sheet = |resolution: u32| TpmsJob {
        structure: Structure::Sheet,
        density: 0.08,
        ..job(0.08, resolution, false)
    };
    match run(sheet(8)) {
        Err(Error::Resolution {
            requested, needed, ..
        }) => {
            assert_eq!(requested, 8);
            let needed = needed.expect("the refusal names a resolution");
            assert!(needed > 8);
            run(sheet(needed)).expect("the resolution named works");
        }
        other => panic!("voxels too coarse for the sheet: {other:?}"),
    }
}
