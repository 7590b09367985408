//! The density promise at every setting latvox accepts: random parts (type, structure, density
//! in the feasible range, resolution, boxes that are not whole cells, cell sizes per axis, any
//! origin), each run as a user runs it. Whatever latvox exits with must be right:
//!
//! - exit 0: the written STL, measured by this test's own divergence-theorem volume, is within
//!   0.002 of the target; it is closed and consistently wound (edges counted here) and one piece
//!   (shells found here, by shared corners);
//! - exit 2 with a fixed resolution: the refusal names a resolution, that resolution works (exit
//!   0, density met) and the one below it, if it is above the requested one, is refused too.
//!
//! Seeded: a failure names its case N, and `LATVOX_CASE=N` runs that case alone. The main tier
//! runs the first 14 of 44 fast cases; the long tier (`cargo test --release --
//! --ignored density_property`) the other thirty, and 20 over the whole feasible range
//! (`LATVOX_SWEEP=1000`: a thousand).

use crate::common::*;
use std::path::Path;

/// Where each type and structure holds together (the solid's feasible range, as latvox's
/// `--help` and refusals state it).
pub(crate) const FEASIBLE: [(&str, &str, f64, f64); 14] = [
    ("p", "net", 0.2138, 1.0),
    ("p", "sheet", 0.0, 1.0),
    ("gyroid", "net", 0.0191, 1.0),
    ("gyroid", "sheet", 0.0, 1.0),
    ("d", "net", 0.0834, 1.0),
    ("d", "sheet", 0.0, 1.0),
    ("iwp", "net", 0.1019, 1.0),
    ("iwp", "sheet", 0.0, 1.0),
    ("s", "net", 0.1164, 1.0),
    ("s", "sheet", 0.0, 1.0),
    ("frd", "net", 0.3359, 1.0),
    ("frd", "sheet", 0.0, 0.4409),
    ("neovius", "net", 0.3388, 1.0),
    ("neovius", "sheet", 0.0, 1.0),
];

#[derive(Debug, Clone)]
struct Case {
    ty: &'static str,
    structure: &'static str,
    density: f64,
    resolution: u32,
    cell: [f64; 3],
    size: [f64; 3],
    origin: [f64; 3],
    fixed: bool,
}

pub(crate) fn round(x: f64, digits: i32) -> f64 {
    let m = 10f64.powi(digits);
    (x * m).round() / m
}

/// A random case; `full` draws densities over the whole feasible range and larger grids.
fn draw(rng: &mut Rng, full: bool) -> Case {
    let (ty, structure, lo, hi) = FEASIBLE[rng.below(14) as usize];
    // The fast cases keep away from the thinnest members, which need fine voxels.
    let (lo, hi) = if full {
        ((lo + 0.005).max(0.02), (hi - 0.005).min(0.97))
    } else if structure == "sheet" {
        (0.2, hi.min(0.8))
    } else {
        (lo + 0.03, 0.9)
    };
    let density = round(rng.uniform(lo, hi), 3);
    let cell = if rng.below(3) == 0 {
        [0; 3].map(|_| round(rng.uniform(3.0, 6.0), 2))
    } else {
        [round(rng.uniform(3.0, 6.0), 2); 3]
    };
    let size = cell.map(|c| {
        // Mostly partial cells; sometimes whole ones.
        let n = if rng.below(5) == 0 {
            (1 + rng.below(3)) as f64
        } else {
            rng.uniform(1.1, 3.5)
        };
        round(c * n, 2)
    });
    let cells_max = (0..3).map(|a| size[a] / cell[a]).fold(0.0, f64::max);
    let grid_max = if full { 220.0 } else { 100.0 };
    let mut resolution = 4 + rng.below(61) as u32;
    while resolution > 4 && cells_max * resolution as f64 > grid_max {
        resolution -= 1;
    }
    Case {
        ty,
        structure,
        density,
        resolution,
        cell,
        size,
        origin: [0; 3].map(|_| round(rng.uniform(-50.0, 50.0), 2)),
        fixed: rng.below(4) == 0,
    }
}

fn list(v: [f64; 3]) -> String {
    format!("{},{},{}", v[0], v[1], v[2])
}

struct Run {
    code: i32,
    stderr: String,
    report: Option<serde_json::Value>,
}

fn run_case(c: &Case, resolution: u32, fixed: bool, dir: &Path) -> Run {
    let stl = dir.join("part.stl");
    let rep = dir.join("part.json");
    let _ = std::fs::remove_file(&stl);
    let _ = std::fs::remove_file(&rep);
    let (cell, size, origin, density, res) = (
        list(c.cell),
        list(c.size),
        list(c.origin),
        c.density.to_string(),
        resolution.to_string(),
    );
    let mut args = vec![
        "tpms",
        "-q",
        "--type",
        c.ty,
        "--structure",
        c.structure,
        "--density",
        &density,
        "--cell-size",
        &cell,
        "--size",
        &size,
        "--origin",
        &origin,
        "--resolution",
        &res,
        // The property is the density, closedness and exit code; the self-intersection search
        // is tested elsewhere (tests/self_intersect.rs).
        "--verify",
        "fast",
        "-o",
        "part.stl",
        "--report",
        "part.json",
    ];
    if fixed {
        args.push("--fixed-resolution");
    }
    let out = run(&args, dir);
    Run {
        code: out.status.code().unwrap_or(-1),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
        report: rep.exists().then(|| json(&rep)),
    }
}

/// Checks a successful run's file; returns a description of what is wrong, if anything.
fn check_written(c: &Case, dir: &Path) -> Option<String> {
    let tris = read_stl(&dir.join("part.stl"));
    let box_volume = c.size[0] * c.size[1] * c.size[2];
    let vf = volume(&tris) / box_volume;
    if (vf - c.density).abs() > 0.002 {
        return Some(format!(
            "density {vf:.5} off the target by {:+.5}",
            vf - c.density
        ));
    }
    let e = edges(&tris);
    if e.boundary + e.non_manifold + e.same_direction != 0 {
        return Some(format!("not closed and consistently wound: {e:?}"));
    }
    let p = pieces(&tris);
    if p != 1 {
        return Some(format!("{p} pieces"));
    }
    None
}

/// The resolution a refusal names: `--resolution N`.
fn named_resolution(stderr: &str) -> Option<u32> {
    let at = stderr.find("--resolution ")? + "--resolution ".len();
    stderr[at..]
        .split(|ch: char| !ch.is_ascii_digit())
        .next()?
        .parse()
        .ok()
}

fn check_case(c: &Case, dir: &Path) -> Option<String> {
    let r = run_case(c, c.resolution, c.fixed, dir);
    match r.code {
        0 => check_written(c, dir).map(|why| {
            let used = r.report.as_ref().map(|j| j["resolution"].clone());
            format!("exit 0 but {why} (resolution used {used:?})")
        }),
        2 if c.fixed => {
            if r.stderr.trim_end().lines().count() != 1 || dir.join("part.stl").exists() {
                return Some(format!("refusal not one line or left a file: {}", r.stderr));
            }
            let Some(named) = named_resolution(&r.stderr) else {
                return Some(format!("refusal names no resolution: {}", r.stderr));
            };
            if named <= c.resolution {
                return Some(format!("refusal names {named}: {}", r.stderr));
            }
            let again = run_case(c, named, true, dir);
            if again.code != 0 {
                return Some(format!(
                    "the named resolution {named} exits {}: {}",
                    again.code, again.stderr
                ));
            }
            if let Some(why) = check_written(c, dir) {
                return Some(format!("at the named resolution {named}: {why}"));
            }
            if named - 1 > c.resolution {
                let below = run_case(c, named - 1, true, dir);
                if below.code == 0 {
                    return Some(format!("{named} is named but {} works too", named - 1));
                }
            }
            None
        }
        code => Some(format!("exit {code}: {}", r.stderr.trim_end())),
    }
}

/// The cases `cases` of the sequence drawn from `seed`.
fn property(seed: u64, cases: std::ops::Range<usize>, full: bool) {
    let dir = tempdir();
    let mut rng = Rng(seed);
    let mut failures = Vec::new();
    let cases = Cases::new(cases);
    for i in 0..cases.end() {
        let c = draw(&mut rng, full);
        if !cases.runs(i) {
            continue;
        }
        let t = std::time::Instant::now();
        let outcome = check_case(&c, dir.path());
        eprintln!(
            "{i:4} {:8} {:5} d={:.3} r={:2}{} cells={:.2}×{:.2}×{:.2} {:.2}s {}",
            c.ty,
            c.structure,
            c.density,
            c.resolution,
            if c.fixed { " fixed" } else { "" },
            c.size[0] / c.cell[0],
            c.size[1] / c.cell[1],
            c.size[2] / c.cell[2],
            t.elapsed().as_secs_f64(),
            outcome.as_deref().unwrap_or("ok")
        );
        if let Some(why) = outcome {
            failures.push(format!("case {i} {c:?}: {why}"));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn random_settings_meet_the_density_or_name_a_resolution_that_does() {
    property(0x1a7_0c5, 0..14, false);
}

#[test]
#[ignore = "long: thirty random settings (cases 14 to 43; the main tier runs 0 to 13)"]
fn every_random_setting_meets_the_density_or_names_a_resolution_that_does() {
    property(0x1a7_0c5, 14..44, false);
}

/// The sweep over the whole feasible range: the first 20 of its thousand cases in the long
/// tier (a few minutes), all thousand with `LATVOX_SWEEP=1000` (about half an hour on two cores).
#[test]
#[ignore = "long: random settings over the whole feasible range (LATVOX_SWEEP=1000: a thousand)"]
fn settings_over_the_whole_feasible_range() {
    let cases = std::env::var("LATVOX_SWEEP")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(20);
    property(0x5eed_2026, 0..cases, true);
}

/// Every type and structure at low density — nets just above the density at which they fall
/// apart (the feasible minimum, +0.005), sheets at 0.15 (a sheet holds together however thin;
/// what limits it is the voxels, raised automatically for walls under 1.25 voxels: thinner
/// sheets are in the thousand-case test) — in a block of 3×3×3 cells and one of 2.5×2.5×2.5:
/// one piece, density within 0.002, closed, each measured here. The main tier makes every net
/// at its minimum in the block of partial cells; the long tier, the rest: every sheet in both
/// blocks, every net in the block of whole cells.
#[test]
fn every_net_down_to_its_feasible_minimum_is_one_piece_at_its_density() {
    feasible_minimum(false);
}

#[test]
#[ignore = "long: every type and structure at its minimum in two blocks (the 21 parts the main tier leaves)"]
fn every_type_down_to_its_feasible_minimum_is_one_piece_at_its_density() {
    feasible_minimum(true);
}

fn feasible_minimum(all: bool) {
    let dir = tempdir();
    let mut failures = Vec::new();
    for (ty, structure, min, _) in FEASIBLE {
        let density = if structure == "sheet" {
            0.15
        } else {
            round(min + 0.005, 4)
        };
        for cells in [3.0, 2.5] {
            // The main tier's parts: the nets in partial cells.
            if all == (structure == "net" && cells == 2.5) {
                continue;
            }
            let c = Case {
                ty,
                structure,
                density,
                resolution: 32,
                cell: [5.0; 3],
                size: [5.0 * cells; 3],
                origin: [0.0; 3],
                fixed: false,
            };
            let r = run_case(&c, 32, false, dir.path());
            let outcome = match r.code {
                0 => check_written(&c, dir.path()),
                code => Some(format!("exit {code}: {}", r.stderr.trim_end())),
            };
            eprintln!(
                "{ty:8} {structure:5} {density:.4} {cells} cells: {}",
                outcome.as_deref().unwrap_or("ok")
            );
            if let Some(why) = outcome {
                failures.push(format!("{ty} {structure} {density} {cells} cells: {why}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
