//! Part files: a part's settings saved with `--save-part` and given back with `--part` make the
//! same part, byte for byte; options on the command line override the file's; a batch job can
//! name one; bad part files are refused in one line with no file written.

use crate::common::*;
use std::path::Path;

fn ok(out: &std::process::Output) {
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap()
}

#[test]
fn a_saved_part_is_made_again_byte_for_byte() {
    let dir = tempdir();
    let d = dir.path();
    // A TPMS part with a short option, a partial cell and an odd origin.
    ok(&run(
        &[
            "tpms",
            "-q",
            "-t",
            "d",
            "--structure",
            "sheet",
            "-d",
            "0.2",
            "--size",
            "12,10,9",
            "--cell-size",
            "5",
            "--origin=-3,1.5,0",
            "-o",
            "a.stl",
            "--save-part",
            "d.toml",
        ],
        d,
    ));
    let text = std::fs::read_to_string(d.join("d.toml")).unwrap();
    assert!(
        text.contains("type = \"d\"") && text.contains("origin = [-3, 1.5, 0]"),
        "{text}"
    );
    assert!(
        !text.contains("a.stl"),
        "where the files go is not part of the part: {text}"
    );
    ok(&run(&["tpms", "-q", "--part", "d.toml", "-o", "b.stl"], d));
    assert_eq!(read(&d.join("a.stl")), read(&d.join("b.stl")));

    // A strut part whose cell file sits beside the part file, made from another folder.
    let sub = d.join("parts");
    std::fs::create_dir(&sub).unwrap();
    std::fs::write(
        sub.join("cell.json"),
        r#"{"nodes": [[0.5,0.5,0.5],[0,0,0],[1,1,1],[1,0,0],[0,1,1],[1,1,0],[0,0,1],[0,1,0],[1,0,1]],
            "struts": [[0,1],[0,2],[0,3],[0,4],[0,5],[0,6],[0,7],[0,8]]}"#,
    )
    .unwrap();
    ok(&run(
        &[
            "strut",
            "-q",
            "--cell",
            "cell.json",
            "--density",
            "0.15",
            "--blend",
            "0.2",
            "--cells",
            "2",
            "-o",
            "c.stl",
            "--save-part",
            "custom.toml",
        ],
        &sub,
    ));
    ok(&run(
        &["strut", "-q", "--part", "parts/custom.toml", "-o", "e.stl"],
        d,
    ));
    assert_eq!(read(&sub.join("c.stl")), read(&d.join("e.stl")));
}

#[test]
fn the_command_line_overrides_the_part_file() {
    let dir = tempdir();
    let d = dir.path();
    std::fs::write(
        d.join("octet.toml"),
        "command = \"strut\"\ncell = \"octet\"\ndensity = 0.2\ncells = 3\ncell-size = 4\n",
    )
    .unwrap();
    ok(&run(
        &[
            "strut",
            "-q",
            "--part",
            "octet.toml",
            "--cells",
            "2",
            "--radius",
            "0.3",
            "-o",
            "o.stl",
            "--report",
            "o.json",
        ],
        d,
    ));
    let r = json(&d.join("o.json"));
    assert_eq!(r["cells"], serde_json::json!([2.0, 2.0, 2.0]));
    assert_eq!(r["cell_size"], serde_json::json!([4.0, 4.0, 4.0]));
    assert_eq!(r["radius"], 0.3);
    assert!(r["target_density"].is_null());
    assert_eq!(r["cell"], "octet");
}

#[test]
fn a_batch_job_names_a_part_file() {
    let dir = tempdir();
    let d = dir.path();
    std::fs::write(
        d.join("bcc.toml"),
        "command = \"strut\"\ncell = \"bcc\"\ndensity = 0.2\ncells = 2\n",
    )
    .unwrap();
    std::fs::write(
        d.join("jobs.toml"),
        "[[sweep]]\ncommand = 'strut'\npart = 'bcc.toml'\ndensity = [0.15, 0.25]\noutput = 'out/{density}.stl'\n",
    )
    .unwrap();
    ok(&run(&["batch", "-q", "jobs.toml"], d));
    for target in [0.15, 0.25] {
        let tris = read_stl(&d.join(format!("out/{target}.stl")));
        let got = volume(&tris) / 1000.0;
        assert!((got - target).abs() <= 0.002, "{target}: {got}");
    }
}

#[test]
fn bad_part_files_are_refused_in_one_line() {
    let dir = tempdir();
    let d = dir.path();
    std::fs::write(d.join("tpms.toml"), "command = \"tpms\"\ntype = \"p\"\n").unwrap();
    std::fs::write(d.join("typo.toml"), "command = \"strut\"\ndensty = 0.2\n").unwrap();
    std::fs::write(d.join("nocommand.toml"), "cell = \"bcc\"\n").unwrap();
    std::fs::write(d.join("broken.toml"), "command = \"strut\"\ncells = \n").unwrap();
    std::fs::write(d.join("table.toml"), "command = \"strut\"\n[cell]\nx = 1\n").unwrap();
    for (file, what) in [
        ("missing.toml", "missing.toml"),
        ("tpms.toml", "latvox tpms"),
        ("typo.toml", "densty"),
        ("nocommand.toml", "command"),
        ("broken.toml", "not a part file"),
        ("table.toml", "cell"),
    ] {
        let out = run(&["strut", "-q", "--part", file, "-o", "x.stl"], d);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{file}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{file}: {err}");
        assert!(err.contains(what), "{file}: '{err}' does not say '{what}'");
        assert!(!d.join("x.stl").exists(), "{file}");
    }
    // An unwritable part file to save is refused before the work.
    let out = run(
        &[
            "strut",
            "-q",
            "--cells",
            "2",
            "-o",
            "y.stl",
            "--save-part",
            "no/such/dir/p.toml",
        ],
        d,
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(!d.join("y.stl").exists());
}
