//! `latvox batch`, run as a user runs it: every job's part checked with computations independent
//! of latvox (`common`: STL reading, edge counting, divergence volume), a batch job compared
//! vertex for vertex with the same job run by `latvox tpms`, `interpret` (and its old name `topo`) and `repair` jobs beside
//! `tpms` ones, a batch killed with SIGKILL and resumed, shards whose union is the whole batch,
//! failures reported and retried.

use crate::common::*;
use crate::meshkit;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::time::{Duration, Instant};

/// `latvox`, without the Slurm array identity the test run itself may have (a test run inside
/// an array task would otherwise shard every batch).
fn lv() -> std::process::Command {
    let mut c = latvox();
    for v in [
        "SLURM_ARRAY_TASK_ID",
        "SLURM_ARRAY_TASK_MIN",
        "SLURM_ARRAY_TASK_MAX",
        "SLURM_ARRAY_TASK_STEP",
        "SLURM_ARRAY_TASK_COUNT",
    ] {
        c.env_remove(v);
    }
    c
}

fn batch(dir: &Path, args: &[&str]) -> std::process::Output {
    lv().arg("batch")
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run latvox batch")
}

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A small sweep: `types` × `densities`, `cells`³ cells of 5 mm at `resolution`.
fn sweep(types: &[&str], densities: &[f64], cells: u32, resolution: u32) -> String {
    let list = |v: Vec<String>| v.join(", ");
    format!(
        "[defaults]\ncells = {cells}\ncell-size = 5\nresolution = {resolution}\n\n\
         [[sweep]]\ncommand = \"tpms\"\noutput = \"out/{{type}}-{{density}}.stl\"\n\
         type = [{}]\ndensity = [{}]\n",
        list(types.iter().map(|t| format!("\"{t}\"")).collect()),
        list(densities.iter().map(|d| d.to_string()).collect()),
    )
}

/// The summary's rows, by job number.
fn summary_rows(path: &Path) -> BTreeMap<u64, serde_json::Value> {
    json(path)["jobs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| (r["job"].as_u64().unwrap(), r.clone()))
        .collect()
}

/// Checks an STL without latvox: complete binary file, every edge shared by exactly two
/// triangles wound oppositely, and the volume fraction of a `side`³ mm box near `density`.
fn assert_valid_part(stl: &Path, density: f64, side: f64) {
    let bytes = std::fs::metadata(stl).unwrap().len();
    let data = std::fs::read(stl).unwrap();
    let n = u32::from_le_bytes(data[80..84].try_into().unwrap()) as u64;
    assert_eq!(bytes, 84 + 50 * n, "{}: truncated or padded", stl.display());
    let tris = read_stl(stl);
    assert_eq!(edges(&tris), Edges::default(), "{}", stl.display());
    let vf = volume(&tris) / side.powi(3);
    assert!(
        (vf - density).abs() < 0.004,
        "{}: volume fraction {vf}, target {density}",
        stl.display()
    );
}

/// The same part: as many triangles, the same bounds and volume. (Not byte for byte: today the
/// calibrated level varies in its last bits with the order of parallel sums, and the diagonal
/// that cuts a quad with thread scheduling, in a batch as from one run of `latvox tpms` to the
/// next.)
fn assert_same_part(a: &Path, b: &Path) {
    let (ta, tb) = (read_stl(a), read_stl(b));
    let what = format!("{} and {}", a.display(), b.display());
    assert_eq!(ta.len(), tb.len(), "{what}");
    let ((la, ha), (lb, hb)) = (bounds(&ta), bounds(&tb));
    for k in 0..3 {
        assert!(
            (la[k] - lb[k]).abs() < 1e-5 && (ha[k] - hb[k]).abs() < 1e-5,
            "{what}"
        );
    }
    let (va, vb) = (volume(&ta), volume(&tb));
    assert!(
        (va - vb).abs() <= 1e-6 * va,
        "{what}: volumes {va} and {vb}"
    );
    let (ra, rb) = (
        json(&a.with_extension("json")),
        json(&b.with_extension("json")),
    );
    let (ka, kb) = (ra["level"].as_f64().unwrap(), rb["level"].as_f64().unwrap());
    assert!((ka - kb).abs() < 1e-9, "{what}: levels {ka} and {kb}");
}

fn temporaries(dir: &Path) -> Vec<PathBuf> {
    files_in(dir)
        .into_iter()
        .filter(|p| {
            p.file_name()
                .unwrap()
                .to_string_lossy()
                .contains(".latvox-")
        })
        .collect()
}

#[test]
fn every_job_is_made_like_the_subcommand_makes_it() {
    let dir = tempdir();
    let d = dir.path();
    let jobs = format!(
        "{}\n[[job]]\ncommand = \"tpms\"\noutput = \"single/d-sheet.stl\"\ntype = \"d\"\n\
         structure = \"sheet\"\ndensity = 0.25\ncells = [2, 2, 2]\ncell_size = 5\nresolution = 16\n",
        sweep(&["gyroid", "p"], &[0.3, 0.4], 2, 16)
    );
    std::fs::write(d.join("jobs.toml"), jobs).unwrap();
    // Run from another folder: paths are relative to the job file.
    let o = batch(
        d.parent().unwrap(),
        &[d.join("jobs.toml").to_str().unwrap(), "-q"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));

    let rows = summary_rows(&d.join("jobs-summary.json"));
    assert_eq!(rows.len(), 5);
    let expect = [
        (1, "single/d-sheet.stl", 0.25),
        (2, "out/gyroid-0.3.stl", 0.3),
        (3, "out/gyroid-0.4.stl", 0.4),
        (4, "out/p-0.3.stl", 0.3),
        (5, "out/p-0.4.stl", 0.4),
    ];
    for (job, output, density) in expect {
        let r = &rows[&job];
        assert_eq!(r["status"], "ok", "{r}");
        assert_eq!(r["output"], output);
        assert_valid_part(&d.join(output), density, 10.0);
        let report = json(&d.join(output).with_extension("json"));
        assert_eq!(report["checks"]["closed"], true);
        assert_eq!(report["target_density"], density);
        let b = &report["batch"];
        assert_eq!(b["job"], job);
        assert_eq!(b["hash"], r["hash"]);
        assert_eq!(b["run_id"], r["run_id"]);
        assert_eq!(b["outcome"], "ok");
        assert_eq!(
            b["outputs"][0]["bytes"].as_u64().unwrap(),
            std::fs::metadata(d.join(output)).unwrap().len()
        );
    }
    let csv = std::fs::read_to_string(d.join("jobs-summary.csv")).unwrap();
    assert_eq!(csv.lines().count(), 6, "{csv}");
    assert!(csv.lines().nth(1).unwrap().starts_with("1,ok,"), "{csv}");

    // The same job by hand: the same options give the same bytes.
    let o = run(
        &[
            "tpms",
            "--type",
            "d",
            "--structure",
            "sheet",
            "--density",
            "0.25",
            "--cells",
            "2,2,2",
            "--cell-size",
            "5",
            "--resolution",
            "16",
            "-q",
            "-o",
            "by-hand.stl",
            "--report",
            "by-hand.json",
        ],
        d,
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_same_part(&d.join("by-hand.stl"), &d.join("single/d-sheet.stl"));
    assert!(temporaries(&d.join("out")).is_empty());
}

/// A 32 × 16 mm plate with an 8 × 4 mm hole, as a density field of 2 mm elements (rows from the
/// top); returns the field's values.
fn write_plate_field(path: &Path) -> Vec<f64> {
    let (ny, nx) = (8, 16);
    let mut field = vec![0.0; nx * ny];
    for y in 1..7 {
        for x in 1..15 {
            let hole = (3..5).contains(&y) && (6..10).contains(&x);
            field[y * nx + x] = if hole { 0.0 } else { 1.0 };
        }
    }
    let mut buf = Vec::new();
    latvox::io::npy::write(&mut buf, &[ny, nx], &field).unwrap();
    std::fs::write(path, buf).unwrap();
    field
}

/// A 10 mm cube, outward, with one facet left out (a hole).
fn write_open_cube(path: &Path) {
    let mut facets = meshkit::cuboid([0.0; 3], [10.0; 3]);
    facets.remove(1);
    meshkit::write_stl(path, &facets);
}

#[test]
fn interpret_and_repair_jobs_make_their_parts_and_are_recorded() {
    let dir = tempdir();
    let d = dir.path();
    let field = write_plate_field(&d.join("plate.npy"));
    write_open_cube(&d.join("open.stl"));
    let jobs =
        "[[job]]\ncommand = \"interpret\"\ninput = \"plate.npy\"\noutput = \"out/plate.stl\"\n\
                element-size = 2\nmin-feature = 1\niges = \"out/plate.igs\"\n\n\
                [[job]]\ncommand = \"topo\"\ninput = \"plate.npy\"\noutput = \"out/thin.stl\"\n\
                element-size = 2\nmin-feature = 6\nmax-iterations = 1\n\n\
                [[job]]\ncommand = \"repair\"\ninput = \"open.stl\"\noutput = \"out/cube.stl\"\n";
    std::fs::write(d.join("jobs.toml"), jobs).unwrap();
    let o = batch(d, &["jobs.toml", "-q"]);
    // The second job's printer limit (6 mm features) is more than one pass can meet.
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));

    let rows = summary_rows(&d.join("jobs-summary.json"));
    let expect = [
        (1, "interpret", "out/plate.stl", "ok"),
        (2, "topo", "out/thin.stl", "defects"),
        (3, "repair", "out/cube.stl", "ok"),
    ];
    for (job, command, output, status) in expect {
        let r = &rows[&job];
        assert_eq!(
            (
                r["command"].as_str(),
                r["output"].as_str(),
                r["status"].as_str()
            ),
            (Some(command), Some(output), Some(status)),
            "{r}"
        );
        let report = json(&d.join(output).with_extension("json"));
        assert_eq!(report["batch"]["outcome"], status);
        assert_eq!(report["batch"]["hash"], r["hash"]);
        // The part is written either way: closed, wound consistently.
        assert_eq!(
            edges(&read_stl(&d.join(output))),
            Edges::default(),
            "{output}"
        );
    }

    // The plate: its volume is the thresholded elements' area times the thickness (one
    // element), counted here from the field; its CAD curves are an output of the job too.
    let solid = field.iter().filter(|&&v| v >= 0.5).count() as f64;
    let v = volume(&read_stl(&d.join("out/plate.stl")));
    assert!((v / (solid * 4.0 * 2.0) - 1.0).abs() < 0.01, "volume {v}");
    let plate = json(&d.join("out/plate.json"));
    assert_eq!(plate["clean"], true);
    let outputs: Vec<(String, u64)> = plate["batch"]["outputs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| {
            (
                o["path"].as_str().unwrap().into(),
                o["bytes"].as_u64().unwrap(),
            )
        })
        .collect();
    let size = |p: &str| std::fs::metadata(d.join(p)).unwrap().len();
    assert_eq!(
        outputs,
        [
            ("out/plate.stl".into(), size("out/plate.stl")),
            ("out/plate.igs".into(), size("out/plate.igs")),
        ]
    );
    assert_eq!(json(&d.join("out/thin.json"))["clean"], false);

    // The cube: its hole filled, the whole 1000 mm³ enclosed.
    let cube = json(&d.join("out/cube.json"));
    assert_eq!(cube["valid_solid"], true);
    let v = volume(&read_stl(&d.join("out/cube.stl")));
    assert!((v - 1000.0).abs() < 1e-6, "volume {v}");

    // The same part as `latvox interpret` makes.
    let o = run(
        &[
            "interpret",
            "plate.npy",
            "--element-size",
            "2",
            "--min-feature",
            "1",
            "-q",
            "-o",
            "by-hand.stl",
            "--report",
            "by-hand.json",
        ],
        d,
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_same_part(&d.join("by-hand.stl"), &d.join("out/plate.stl"));

    // Every output counts: without its curves the plate runs again; the cube does not.
    std::fs::remove_file(d.join("out/plate.igs")).unwrap();
    let o = batch(d, &["jobs.toml", "-q"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let rows = summary_rows(&d.join("jobs-summary.json"));
    let status: Vec<&str> = rows
        .values()
        .map(|r| r["status"].as_str().unwrap())
        .collect();
    assert_eq!(status, ["ok", "defects", "skipped"]);
    assert!(d.join("out/plate.igs").is_file());
    assert!(temporaries(&d.join("out")).is_empty());
}

#[test]
fn a_killed_batch_resumes_without_running_a_finished_job_again() {
    let dir = tempdir();
    let d = dir.path();
    let densities = [0.2, 0.25, 0.3, 0.35, 0.4, 0.45];
    std::fs::write(
        d.join("jobs.toml"),
        sweep(&["gyroid", "d"], &densities, 3, 28),
    )
    .unwrap();
    let total = 12;
    let mut child = lv()
        .args(["batch", "jobs.toml", "--workers", "2", "-q"])
        .current_dir(d)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Kill it once a few jobs are done and others are under way.
    let reports = || {
        std::fs::read_dir(d.join("out"))
            .map(|r| {
                r.filter(|e| {
                    e.as_ref()
                        .unwrap()
                        .path()
                        .extension()
                        .is_some_and(|x| x == "json")
                })
                .count()
            })
            .unwrap_or(0)
    };
    let start = Instant::now();
    while reports() < 3 {
        assert!(
            child.try_wait().unwrap().is_none(),
            "the batch ended before it could be killed: make its jobs bigger"
        );
        assert!(start.elapsed() < Duration::from_secs(120), "no progress");
        std::thread::sleep(Duration::from_millis(10));
    }
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();

    // What the killed run left: complete outputs only, and a report only after its output.
    let out = d.join("out");
    let mut finished = BTreeMap::new();
    for p in files_in(&out) {
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if name.starts_with('.') {
            continue;
        }
        if name.ends_with(".json") {
            let r = json(&p);
            let stl = p.with_extension("stl");
            assert!(stl.exists(), "{name} without its STL");
            let mtime = std::fs::metadata(&stl).unwrap().modified().unwrap();
            finished.insert(
                name,
                (
                    r["batch"]["run_id"].clone(),
                    std::fs::read(&p).unwrap(),
                    mtime,
                ),
            );
        } else {
            let density: f64 = name
                .trim_end_matches(".stl")
                .rsplit('-')
                .next()
                .unwrap()
                .parse()
                .unwrap();
            assert_valid_part(&p, density, 15.0);
        }
    }
    assert!(
        finished.len() >= 3 && finished.len() < total,
        "{} of {total} jobs finished before the kill",
        finished.len()
    );

    let o = batch(d, &["jobs.toml", "--workers", "2", "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let rows = summary_rows(&d.join("jobs-summary.json"));
    assert_eq!(rows.len(), total);
    let mut ran = 0;
    for r in rows.values() {
        let report_name = Path::new(r["report"].as_str().unwrap())
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        match finished.get(&report_name) {
            Some((run_id, bytes, mtime)) => {
                // Finished before the kill: not run again, its report and part untouched.
                assert_eq!(r["status"], "skipped", "{r}");
                assert_eq!(&r["run_id"], run_id, "{r}");
                assert_eq!(
                    &std::fs::read(d.join(r["report"].as_str().unwrap())).unwrap(),
                    bytes
                );
                let stl = d.join(r["output"].as_str().unwrap());
                assert_eq!(&std::fs::metadata(&stl).unwrap().modified().unwrap(), mtime);
            }
            None => {
                assert_eq!(r["status"], "ok", "{r}");
                ran += 1;
            }
        }
    }
    assert_eq!(ran, total - finished.len());
    for (i, (ty, density)) in ["gyroid", "d"]
        .iter()
        .flat_map(|t| densities.iter().map(move |d| (t, d)))
        .enumerate()
    {
        let stl = out.join(format!("{ty}-{density}.stl"));
        assert_valid_part(&stl, *density, 15.0);
        let report = json(&stl.with_extension("json"));
        assert_eq!(report["batch"]["job"], i + 1);
        assert_eq!(report["batch"]["run_id"], rows[&(i as u64 + 1)]["run_id"]);
    }
    assert!(temporaries(&out).is_empty(), "{:?}", temporaries(&out));
}

#[test]
fn the_union_of_the_shards_is_the_whole_batch() {
    let dir = tempdir();
    let (whole, parts) = (dir.path().join("whole"), dir.path().join("parts"));
    let jobs = sweep(&["gyroid", "iwp"], &[0.3, 0.35, 0.4], 2, 16);
    for d in [&whole, &parts] {
        std::fs::create_dir(d).unwrap();
        std::fs::write(d.join("jobs.toml"), &jobs).unwrap();
    }
    let o = batch(&whole, &["jobs.toml", "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));

    // Three shards at once, as a job array would run them: two by --shard, one by Slurm's
    // variables (an array 1-3, so task 2 is shard 2/3).
    let spawn = |args: &[&str], env: &[(&str, &str)]| {
        lv().arg("batch")
            .args(args)
            .args(["--threads", "1", "-q"])
            .envs(env.iter().copied())
            .current_dir(&parts)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    let shards = [
        spawn(&["jobs.toml", "--shard", "1/3"], &[]),
        spawn(
            &["jobs.toml"],
            &[
                ("SLURM_ARRAY_TASK_ID", "2"),
                ("SLURM_ARRAY_TASK_MIN", "1"),
                ("SLURM_ARRAY_TASK_MAX", "3"),
                ("SLURM_ARRAY_TASK_STEP", "1"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ],
        ),
        spawn(&["jobs.toml", "--shard", "3/3"], &[]),
    ];
    for c in shards {
        let o = c.wait_with_output().unwrap();
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }

    let mut seen = BTreeSet::new();
    for k in 1..=3 {
        let rows = summary_rows(&parts.join(format!("jobs-summary-shard-{k}-of-3.json")));
        assert_eq!(rows.len(), 2, "shard {k}");
        for (job, r) in rows {
            assert_eq!(r["status"], "ok");
            assert_eq!((job - 1) % 3, k - 1, "job {job} in shard {k}");
            assert!(seen.insert(job), "job {job} ran in two shards");
            let report = json(&parts.join(r["report"].as_str().unwrap()));
            assert_eq!(report["batch"]["shard"], format!("{k}/3"));
        }
    }
    assert_eq!(seen, (1..=6).collect());
    let names = |d: &Path| -> Vec<String> {
        files_in(&d.join("out"))
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect()
    };
    assert_eq!(names(&whole), names(&parts));
    assert_eq!(names(&whole).len(), 12);
    let whole_rows = summary_rows(&whole.join("jobs-summary.json"));
    for name in names(&whole).iter().filter(|n| n.ends_with(".stl")) {
        let (a, b) = (whole.join("out").join(name), parts.join("out").join(name));
        assert_same_part(&a, &b);
        let (ra, rb) = (
            json(&a.with_extension("json")),
            json(&b.with_extension("json")),
        );
        assert_eq!(ra["batch"]["hash"], rb["batch"]["hash"]);
        let job = ra["batch"]["job"].as_u64().unwrap();
        assert_eq!(whole_rows[&job]["hash"], ra["batch"]["hash"]);
    }
}

#[test]
fn failed_and_changed_jobs_run_again_done_ones_do_not() {
    let dir = tempdir();
    let d = dir.path();
    // Job 2 asks for an F-RD network at 10 %, where the solid falls apart: refused.
    let file = |frd: &str, p_density: f64| {
        format!(
            "[defaults]\ncells = 2\nresolution = 16\n\n\
             [[job]]\ncommand = \"tpms\"\noutput = \"p.stl\"\ntype = \"p\"\ndensity = {p_density}\n\n\
             [[job]]\ncommand = \"tpms\"\noutput = \"frd.stl\"\ntype = \"frd\"\n{frd}\n\n\
             [[job]]\ncommand = \"tpms\"\noutput = \"g.stl\"\ntype = \"g\"\ndensity = 0.3\n"
        )
    };
    std::fs::write(d.join("jobs.toml"), file("density = 0.1", 0.35)).unwrap();
    // A temporary left by an earlier, killed run of job 2.
    std::fs::write(d.join(".frd.stl.latvox-Ab12Cd"), b"half a part").unwrap();
    let o = batch(d, &["jobs.toml", "-q"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("failed") && stdout.contains("feasible range"),
        "{stdout}"
    );
    let rows = summary_rows(&d.join("jobs-summary.json"));
    assert_eq!(rows[&1]["status"], "ok");
    assert_eq!(rows[&2]["status"], "failed");
    assert!(
        rows[&2]["error"].as_str().unwrap().contains("islands"),
        "{}",
        rows[&2]
    );
    assert_eq!(rows[&3]["status"], "ok");
    assert!(!d.join("frd.stl").exists() && !d.join("frd.json").exists());
    assert!(temporaries(d).is_empty(), "{:?}", temporaries(d));
    let csv = std::fs::read_to_string(d.join("jobs-summary.csv")).unwrap();
    assert!(
        csv.lines().nth(2).unwrap().starts_with("2,failed,"),
        "{csv}"
    );
    let run_id = |rows: &BTreeMap<u64, serde_json::Value>, j: u64| rows[&j]["run_id"].clone();
    let first = rows;

    // Again: only the failed job runs (and fails again).
    let o = batch(d, &["jobs.toml", "-q"]);
    assert_eq!(o.status.code(), Some(1));
    let rows = summary_rows(&d.join("jobs-summary.json"));
    assert_eq!(rows[&1]["status"], "skipped");
    assert_eq!(rows[&2]["status"], "failed");
    assert_eq!(rows[&3]["status"], "skipped");
    assert_eq!(run_id(&rows, 1), run_id(&first, 1));

    // Fixed job 2, changed job 1, and job 3's part damaged since: those three run, nothing else.
    std::fs::write(d.join("jobs.toml"), file("density = 0.4", 0.4)).unwrap();
    let g = std::fs::read(d.join("g.stl")).unwrap();
    std::fs::write(d.join("g.stl"), &g[..g.len() / 2]).unwrap();
    let o = batch(d, &["jobs.toml", "-q", "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["counts"]["ok"], 3, "{v}");
    assert_valid_part(&d.join("p.stl"), 0.4, 10.0);
    assert_valid_part(&d.join("frd.stl"), 0.4, 10.0);
    assert_valid_part(&d.join("g.stl"), 0.3, 10.0);
    assert_ne!(v["jobs"][0]["run_id"], run_id(&first, 1));

    // Everything done: nothing runs, unless forced.
    let o = batch(d, &["jobs.toml", "-q", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["counts"]["skipped"], 3, "{v}");
    let o = batch(
        d,
        &["jobs.toml", "-q", "--json", "--force", "--shard", "2/3"],
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["counts"]["ok"], 1, "{v}");
    assert_eq!(v["jobs"][0]["job"], 2, "{v}");
}

#[test]
fn a_bad_job_file_runs_nothing_and_says_where() {
    let dir = tempdir();
    let d = dir.path();
    let cases: [(&str, &[&str]); 6] = [
        (
            "[[job]]\ncommand = \"tpms\"\noutput = \"a.stl\"\n[[job]]\ncommand = \"tpms\"\noutput = \"b.stl\"\ncell_sise = 5\n",
            &["job 2 (tpms)", "'--cell-sise'", "'--cell-size'"],
        ),
        (
            "[[job]]\ncommand = \"tpms\"\noutput = \"a.stl\"\ndensity = 1.2\n",
            &["job 1 (tpms)", "density must be strictly between 0 and 1"],
        ),
        (
            "[[job]]\ncommand = \"check\"\noutput = \"a.stl\"\n",
            &["'check' is not a subcommand a job can run", "tpms"],
        ),
        (
            "[[sweep]]\ncommand = \"tpms\"\noutput = \"{type}.stl\"\ntype = [\"g\", \"d\"]\ndensity = [0.2, 0.3]\n",
            &["both write 'g.stl'", "add a {key}"],
        ),
        ("[[job]]\ncommand = \"tpms\"\noutput = \"a.stl\"\ndensity = \n", &["line 4"]),
        (
            "[[job]]\ncommand = \"tpms\"\noutput = \"a.stl\"\nascii = \"yes\"\n",
            &["'ascii' is a switch"],
        ),
    ];
    for (text, want) in cases {
        std::fs::write(d.join("bad.toml"), text).unwrap();
        let o = batch(d, &["bad.toml"]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{text}: {e}");
        assert_eq!(e.lines().count(), 1, "{e}");
        assert!(e.starts_with("latvox: bad.toml: "), "{e}");
        for w in want {
            assert!(e.contains(w), "{text}: {e} lacks {w}");
        }
    }
    let o = batch(d, &["bad.toml", "--shard", "4/3"]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        files_in(d),
        vec![d.join("bad.toml")],
        "nothing may be written"
    );
}

#[test]
fn dry_run_lists_the_jobs_and_writes_nothing() {
    let dir = tempdir();
    let d = dir.path();
    std::fs::write(d.join("jobs.toml"), sweep(&["s", "n"], &[0.3, 0.4], 2, 16)).unwrap();
    let o = batch(d, &["jobs.toml", "--dry-run", "--json", "--shard", "1/2"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let jobs: Vec<(u64, &str)> = v
        .as_array()
        .unwrap()
        .iter()
        .map(|j| (j["job"].as_u64().unwrap(), j["output"].as_str().unwrap()))
        .collect();
    assert_eq!(jobs, [(1, "out/s-0.3.stl"), (3, "out/n-0.3.stl")]);
    assert_eq!(v[1]["options"]["cells"], 2);
    assert_eq!(v[1]["done"], false);
    assert_eq!(files_in(d), vec![d.join("jobs.toml")]);
}
