//! Mesh check and repair benchmarks, with the figures quoted in README.
//!
//! The part: a torus of 1000 × 500 quads, 1,000,000 facets, written as binary STL (50 MB).
//! 1. Reading it (`latvox::io::read`: parse, exact weld) in-process, and admesh on the same
//!    file: `admesh -c` (read only, no checks) and `admesh` (its default checks and repairs).
//! 2. `check` (every count, the self-intersection search included) and `repair` on the clean
//!    part, and on a damaged copy (1 % of facets reversed, 20 holes cut out).
//! 3. The self-intersection search alone: latvox's (which `check` uses) beside CGAL's, one
//!    search of the whole part and the tiled parallel search (same pairs, all three).
//! 4. The whole `latvox repair` command on the damaged copy (read, check, repair, write, read the
//!    written file back and check it again), as a user runs it.
//!
//! 5. `latvox repair --solid` on the damaged copy and on the worst slicer mesh of the test corpus
//!    (wall time and peak memory of the command).
//!
//! Medians of several runs, wall time and (in-process) CPU time of all threads. Run: `cargo bench --bench check` (add `-- --runs N`; `-- --solid-only` for section 5 alone).

use latvox::check::{check, CheckOptions};
use latvox::io::{ReadOptions, StlFormat};
use latvox::progress::Progress;
use latvox::repair::{repair, RepairOptions};
use std::process::Command;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

/// CPU seconds (user + system) used by this process so far, all threads.
fn cpu_seconds() -> f64 {
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: getrusage fills the struct we own.
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    let tv = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    tv(u.ru_utime) + tv(u.ru_stime)
}

thread_local! {
    /// Median CPU seconds of the last `time` call (the machine is shared: wall time alone varies
    /// with the load from other work, CPU time much less).
    static LAST_CPU: std::cell::Cell<f64> = const { std::cell::Cell::new(0.0) };
}

fn time<T>(runs: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut times = Vec::new();
    let mut cpu = Vec::new();
    let mut last = None;
    for _ in 0..runs {
        let (t, c) = (Instant::now(), cpu_seconds());
        last = Some(f());
        times.push(t.elapsed().as_secs_f64());
        cpu.push(cpu_seconds() - c);
    }
    LAST_CPU.with(|l| l.set(median(cpu)));
    (median(times), last.expect("at least one run"))
}

mod support;

fn cpu() -> f64 {
    LAST_CPU.with(|l| l.get())
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs = args
        .iter()
        .position(|a| a == "--runs")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(5usize);
    let threads = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    println!("machine: {threads} threads; {runs} runs per case, median reported");
    let dir = tempfile::tempdir().unwrap();
    let clean_path = dir.path().join("torus-1m.stl");
    let clean = support::torus(40.0, 15.0, 1000, 500);
    assert_eq!(clean.triangle_count(), 1_000_000);
    assert!(clean.volume() > 0.0);
    latvox::io::stl::save(&clean, StlFormat::Binary, &clean_path).unwrap();

    // Damaged copy: every 100th facet reversed, and 20 patches of facets cut out.
    let mut damaged = clean.clone();
    for t in damaged.indices.chunks_exact_mut(3).step_by(100) {
        t.swap(1, 2);
    }
    let mut keep = vec![true; damaged.triangle_count()];
    for h in 0..20 {
        let (i0, j0) = (50 * h, 25 * (h % 20));
        for i in i0..i0 + 4 {
            for j in j0..j0 + 4 {
                let q = i * 500 + j;
                keep[2 * q] = false;
                keep[2 * q + 1] = false;
            }
        }
    }
    damaged.indices = damaged
        .indices
        .chunks_exact(3)
        .zip(&keep)
        .filter(|(_, k)| **k)
        .flat_map(|(t, _)| t.to_vec())
        .collect();
    let damaged_path = dir.path().join("torus-1m-damaged.stl");
    latvox::io::stl::save(&damaged, StlFormat::Binary, &damaged_path).unwrap();
    if args.iter().any(|a| a == "--solid-only") {
        solid_section(&damaged_path, runs);
        return;
    }

    println!("\n1. reading a {}-facet binary STL", clean.triangle_count());
    let (t_read, loaded) = time(runs, || {
        latvox::io::read(&clean_path, &ReadOptions::default()).unwrap()
    });
    println!(
        "  latvox read (parse + exact weld)     {t_read:.3} s   (CPU {:.3} s; {} vertices)",
        cpu(),
        loaded.mesh.vertex_count()
    );
    let admesh = |flags: &[&str]| {
        time(runs, || {
            let s = Command::new("admesh")
                .args(flags)
                .arg(&clean_path)
                .output()
                .expect("admesh (scripts/install-deps.sh)");
            assert!(s.status.success());
        })
        .0
    };
    let a_read = admesh(&["-c"]);
    println!("  admesh -c (read, no checks)          {a_read:.3} s");
    let a_all = admesh(&[]);
    println!("  admesh (default checks and repairs)  {a_all:.3} s");

    println!("\n2. check and repair in-process");
    let progress = Progress::hidden();
    for (label, mesh) in [
        ("clean", &loaded.mesh),
        ("damaged", &{
            latvox::io::read(&damaged_path, &ReadOptions::default())
                .unwrap()
                .mesh
        }),
    ] {
        let (t_check, rep) = time(runs, || {
            check(mesh, None, &CheckOptions::default()).unwrap()
        });
        let c_check = cpu();
        let (t_fast, _) = time(runs, || {
            check(
                mesh,
                None,
                &CheckOptions {
                    self_intersections: false,
                    ..CheckOptions::default()
                },
            )
            .unwrap()
        });
        let c_fast = cpu();
        let (t_repair, (fixed, report)) = time(runs, || {
            repair(mesh, &RepairOptions::default(), &progress).unwrap()
        });
        let c_repair = cpu();
        let after = check(&fixed, None, &CheckOptions::default()).unwrap();
        println!(
            "  {label:8} check {t_check:.3} s (without self-intersections {t_fast:.3} s)  repair {t_repair:.3} s",
        );
        println!(
            "           check + repair {:.3} s; without the self-intersection test {:.3} s",
            t_check + t_repair,
            t_fast + t_repair
        );
        println!(
            "           CPU: check {c_check:.3} s, without self-intersections {c_fast:.3} s, repair {c_repair:.3} s",
        );
        println!(
            "           defects before: {:?}; changes: {}; valid after: {}",
            rep.defects(),
            report
                .changes
                .iter()
                .map(|c| format!("{} {}", c.count, c.kind))
                .collect::<Vec<_>>()
                .join(", "),
            after.valid_solid
        );
    }

    println!(
        "\n3. The self-intersection search alone on the clean part: latvox's (grid, exact tests),"
    );
    println!(
        "   and CGAL's on the whole mesh at once (one sequential search) and in tiles in parallel"
    );
    let mesh = &loaded.mesh;
    let all: Vec<u32> = (0..mesh.triangle_count() as u32).collect();
    let (t_ours, ours) = time(runs, || {
        latvox::verify::self_intersect::soup_self_intersections(mesh, &all, 16)
    });
    let c_ours = cpu();
    let (t_whole, whole) = time(runs, || {
        latvox::verify::self_intersect::soup_self_intersections_in_tiles(mesh, &all, None, 16, 0)
            .unwrap()
    });
    let c_whole = cpu();
    let (t_tiled, tiled) = time(runs, || {
        latvox::verify::self_intersect::cgal_soup_self_intersections(mesh, &all, None, 16).unwrap()
    });
    let c_tiled = cpu();
    assert_eq!(whole, tiled);
    assert_eq!(ours, tiled);
    println!(
        "  latvox {t_ours:.3} s (CPU {c_ours:.3} s)   CGAL whole {t_whole:.3} s (CPU {c_whole:.3} s)   CGAL tiled {t_tiled:.3} s (CPU {c_tiled:.3} s)   pairs {}",
        whole.0
    );

    println!("\n4. the latvox repair command on the damaged part");
    let exe = env!("CARGO_BIN_EXE_latvox");
    let out = dir.path().join("fixed.stl");
    let (t_cli, _) = time(runs, || {
        let s = Command::new(exe)
            .args(["repair", "-q"])
            .arg(&damaged_path)
            .arg("-o")
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(
            s.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&s.stdout)
        );
    });
    println!("  latvox repair (read, check, repair, write, re-read, check)  {t_cli:.3} s");

    solid_section(&damaged_path, runs);
}

/// 5. `repair --solid` on the damaged part and on the worst slicer mesh, as a user runs it.
fn solid_section(damaged_path: &std::path::Path, runs: usize) {
    let exe = env!("CARGO_BIN_EXE_latvox");
    let dir = tempfile::tempdir().unwrap();
    println!(
        "\n5. latvox repair --solid (wall time and peak memory of the command, /usr/bin/time)"
    );
    let cura = std::path::Path::new("/usr/local/share/latvox/slicer-meshes/cura");
    let (bq, bee) = (
        cura.join("bq_hephestos_2_platform.3mf"),
        cura.join("BEEVERYCREATIVE-helloBEEprusa.3mf"),
    );
    // The two slowest of the slicer corpus (unions that do not finish, groups remeshed).
    for (name, input) in [
        ("the damaged 1 M-facet part", damaged_path),
        ("bq_hephestos_2_platform.3mf (Debian's cura)", bq.as_path()),
        (
            "BEEVERYCREATIVE-helloBEEprusa.3mf (Debian's cura)",
            bee.as_path(),
        ),
    ] {
        if !input.exists() {
            println!("  {name}: missing (scripts/install-deps.sh unpacks the slicers' meshes)");
            continue;
        }
        let out = dir.path().join("solid.stl");
        let mut walls = Vec::new();
        let mut peaks = Vec::new();
        let mut last = String::new();
        for _ in 0..runs {
            let s = Command::new("/usr/bin/time")
                .args(["-f", "%e %M", exe, "repair", "-q", "--solid", "--json"])
                .arg(input)
                .arg("-o")
                .arg(&out)
                .output()
                .unwrap();
            assert_eq!(s.status.code(), Some(0), "{name}");
            let err = String::from_utf8_lossy(&s.stderr);
            let mut f = err.split_whitespace().rev();
            peaks.push(f.next().unwrap().parse::<f64>().unwrap() / 1024.0);
            walls.push(f.next().unwrap().parse::<f64>().unwrap());
            last = String::from_utf8_lossy(&s.stdout).into_owned();
        }
        let v: serde_json::Value = serde_json::from_str(&last).unwrap();
        println!(
            "  {name}: {:.2} s, peak {:.0} MB; facets {} → {}; solid steps {}; valid {}",
            median(walls),
            median(peaks),
            v["before"]["facets"],
            v["after"]["facets"],
            v["repair"]["solid"],
            v["valid_solid"]
        );
    }
}
