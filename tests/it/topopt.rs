//! `latvox topopt` against faithful NumPy/SciPy transcriptions of the published codes
//! (`tests/reference/top88.py`, `tests/reference/top3d.py`): the same compliance history — first
//! iteration to 1e-4 relative, converged value to 0.5 % — and the same densities.

use crate::common::*;
use std::path::Path;
use std::process::Command;

fn python(script: &str, args: &[String]) -> serde_json::Value {
    let dir = tempdir();
    let out = dir.path().join("ref.json");
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/reference")
        .join(script);
    let o = Command::new("python3")
        .arg(&path)
        .args(args)
        .arg(&out)
        .output()
        .expect("python3 is needed for the reference optimisers (scripts/install-deps.sh)");
    assert!(
        o.status.success(),
        "{script}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    json(&out)
}

fn latvox_topopt(args: &[&str]) -> (serde_json::Value, Vec<f64>) {
    let dir = tempdir();
    let npy = dir.path().join("x.npy");
    let rep = dir.path().join("r.json");
    let mut a: Vec<&str> = vec!["topopt", "-q"];
    a.extend_from_slice(args);
    a.extend([
        "-o",
        npy.to_str().unwrap(),
        "--report",
        rep.to_str().unwrap(),
    ]);
    let o = run(&a, dir.path());
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let arr = latvox::io::npy::parse(&std::fs::read(&npy).unwrap()).unwrap();
    (json(&rep), arr.data)
}

fn compare(name: &str, ours: &serde_json::Value, reference: &serde_json::Value) {
    let c: Vec<f64> = serde_json::from_value(ours["compliance"].clone()).unwrap();
    let r: Vec<f64> = serde_json::from_value(reference["compliance"].clone()).unwrap();
    assert_eq!(ours["iterations"].as_u64().unwrap() as usize, c.len());
    let first = (c[0] - r[0]).abs() / r[0];
    let last = (c.last().unwrap() - r.last().unwrap()).abs() / r.last().unwrap();
    eprintln!(
        "{name}: first {:.10} vs {:.10} (rel {first:.1e}); converged {:.6} vs {:.6} (rel {last:.1e}); iterations {} vs {}",
        c[0],
        r[0],
        c.last().unwrap(),
        r.last().unwrap(),
        c.len(),
        r.len()
    );
    assert!(first <= 1e-4, "{name}: first iteration differs by {first}");
    assert!(
        last <= 0.005,
        "{name}: converged compliance differs by {last}"
    );
    // Same history, iteration by iteration, while both run.
    for (i, (a, b)) in c.iter().zip(&r).enumerate() {
        assert!(
            (a - b).abs() / b < 1e-4,
            "{name}: iteration {}: {a} vs {b}",
            i + 1
        );
    }
}

#[test]
fn mbb_beam_matches_the_88_line_code_with_both_filters() {
    for (ft, filter) in [(1, "sensitivity"), (2, "density")] {
        let (ours, _) = latvox_topopt(&[
            "--problem",
            "mbb",
            "--nelx",
            "60",
            "--nely",
            "20",
            "--volfrac",
            "0.5",
            "--penal",
            "3",
            "--rmin",
            "1.5",
            "--filter",
            filter,
        ]);
        let args = ["60", "20", "0.5", "3", "1.5", &ft.to_string()].map(String::from);
        let reference = python("top88.py", &args);
        compare(&format!("MBB 60x20 {filter} filter"), &ours, &reference);
        assert_eq!(ours["iterations"], reference["iterations"]);
    }
}

#[test]
fn cantilever_3d_matches_top3d() {
    let (ours, x) = latvox_topopt(&[
        "--problem",
        "cantilever3d",
        "--nelx",
        "16",
        "--nely",
        "6",
        "--nelz",
        "3",
        "--volfrac",
        "0.3",
        "--rmin",
        "1.5",
    ]);
    let dir = tempdir();
    let npy = dir.path().join("ref.npy");
    let args = [
        "16".into(),
        "6".into(),
        "3".into(),
        "0.3".into(),
        "3".into(),
        "1.5".into(),
    ];
    let mut full: Vec<String> = args.to_vec();
    // top3d.py takes OUT.json then OUT.npy; `python` appends OUT.json last, so write the npy
    // through a second run with both outputs named here.
    let out = dir.path().join("ref.json");
    full.push(out.display().to_string());
    full.push(npy.display().to_string());
    let o = Command::new("python3")
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/reference/top3d.py"))
        .args(&full)
        .output()
        .expect("python3");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    compare("top3d cantilever 16x6x3", &ours, &json(&out));
    let r = latvox::io::npy::parse(&std::fs::read(&npy).unwrap()).unwrap();
    assert_eq!(r.shape, vec![6, 16, 3]);
    let worst = r
        .data
        .iter()
        .zip(&x)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-4, "densities differ by {worst}");
}

#[test]
fn problem_file_reproduces_the_builtin_cantilever() {
    let dir = tempdir();
    let toml = dir.path().join("c.toml");
    std::fs::write(
        &toml,
        "nelx = 30\nnely = 10\nvolfrac = 0.3\n\
         [[support]]\nx = [0, 0]\ny = [0, 10]\nfix = \"xy\"\n\
         [[load]]\nx = [30, 30]\ny = [0, 0]\nf = [0.0, -1.0]\n",
    )
    .unwrap();
    let (a, xa) = latvox_topopt(&["--problem", toml.to_str().unwrap()]);
    let (b, xb) = latvox_topopt(&["--problem", "cantilever"]);
    assert_eq!(a["compliance"], b["compliance"]);
    assert_eq!(xa, xb);
    // Seed 003's cantilever: 30 x 10 elements of 4 mm at volume fraction 0.3.
    assert_eq!(b["element_size"], 4.0);
    let v: f64 = xb.iter().sum::<f64>() / xb.len() as f64;
    assert!((v - 0.3).abs() < 1e-3, "volume {v}");
}

#[test]
fn bad_problems_and_arguments_exit_2_with_one_line() {
    let dir = tempdir();
    let bad = dir.path().join("bad.toml");
    std::fs::write(
        &bad,
        "nelx = 10\nnely = 5\n[[load]]\nx = [10, 10]\ny = [0, 0]\nf = [0.0, -1.0]\n",
    )
    .unwrap();
    for args in [
        vec!["topopt", "--problem", "bogus"],
        vec!["topopt", "--volfrac", "1.5"],
        vec!["topopt", "--problem", "mbb", "--nelx", "10"],
        vec!["topopt", "--problem", bad.to_str().unwrap()],
        vec![
            "topopt",
            "--problem",
            "mbb",
            "--nelz",
            "3",
            "--nelx",
            "4",
            "--nely",
            "2",
        ],
    ] {
        let o = run(&args, dir.path());
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.starts_with("latvox: ") && err.trim_end().lines().count() == 1,
            "{err}"
        );
    }
    assert!(files_in(dir.path()).iter().all(|p| p.ends_with("bad.toml")));
}
