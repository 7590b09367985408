//! Tiled, streamed meshing: a part meshed tile by tile is the same solid as the part meshed at
//! once — the same triangles, bit for bit (compared here as sorted records read from the two
//! files), so the same volume; both closed and manifold by an edge count independent of latvox.

mod common;
use common::*;

/// The triangles of a binary STL as sorted byte records (corners only, normals dropped).
fn records(path: &std::path::Path) -> Vec<[u8; 36]> {
    let d = std::fs::read(path).unwrap();
    let n = u32::from_le_bytes(d[80..84].try_into().unwrap()) as usize;
    assert_eq!(
        d.len(),
        84 + 50 * n,
        "{}: size and count disagree",
        path.display()
    );
    let mut v: Vec<[u8; 36]> = (0..n)
        .map(|i| d[84 + 50 * i + 12..84 + 50 * i + 48].try_into().unwrap())
        .collect();
    v.sort_unstable();
    v
}

#[test]
fn tiled_and_untiled_parts_are_the_same_solid() {
    let dir = tempdir();
    for (ty, st, tile) in [("gyroid", "net", "32"), ("d", "sheet", "48")] {
        let ctx = format!("{ty} {st}");
        let common = [
            "tpms",
            "-t",
            ty,
            "--structure",
            st,
            "-d",
            "0.3",
            "--cells",
            "6",
            "--resolution",
            "16",
            "--no-instancing",
            "-q",
        ];
        let mut whole = common.to_vec();
        whole.extend(["-o", "whole.stl", "--report", "whole.json"]);
        let mut tiled = common.to_vec();
        tiled.extend(["--tile", tile, "-o", "tiled.stl", "--report", "tiled.json"]);
        for args in [&whole, &tiled] {
            let o = run(args, dir.path());
            assert_eq!(
                o.status.code(),
                Some(0),
                "{ctx}: {}",
                String::from_utf8_lossy(&o.stderr)
            );
        }
        let (rw, rt) = (
            json(&dir.path().join("whole.json")),
            json(&dir.path().join("tiled.json")),
        );
        assert!(rw["tiling"].is_null(), "{ctx}");
        assert!(
            rt["tiling"]["tiles"].as_u64().unwrap() > 8,
            "{ctx}: {}",
            rt["tiling"]
        );
        assert_eq!(rt["checks"]["closed"], true, "{ctx}");
        assert_eq!(rt["checks"]["self_intersecting"], false, "{ctx}");

        let (a, b) = (dir.path().join("whole.stl"), dir.path().join("tiled.stl"));
        assert!(
            records(&a) == records(&b),
            "{ctx}: tiled triangles differ from untiled"
        );
        let (ta, tb) = (read_stl(&a), read_stl(&b));
        assert_eq!(edges(&ta), Edges::default(), "{ctx}: untiled");
        assert_eq!(edges(&tb), Edges::default(), "{ctx}: tiled");
        let (va, vb) = (volume(&ta), volume(&tb));
        assert!((va - vb).abs() <= 1e-6 * va, "{ctx}: {va} vs {vb}");
        assert_eq!(rw["vertices"], rt["vertices"], "{ctx}");
    }
}

/// A memory budget too small for the part's grid sends it through tiles on its own.
#[test]
fn a_small_memory_budget_tiles_the_part() {
    let dir = tempdir();
    let o = run(
        &[
            "tpms",
            "-t",
            "p",
            "-d",
            "0.4",
            "--cells",
            "4",
            "--resolution",
            "24",
            "--no-instancing",
            "--memory",
            "40M",
            "-q",
            "-o",
            "p.stl",
            "--report",
            "p.json",
        ],
        dir.path(),
    );
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let r = json(&dir.path().join("p.json"));
    assert!(
        r["tiling"]["tiles"].as_u64().unwrap() > 1,
        "{}",
        r["tiling"]
    );
    let t = read_stl(&dir.path().join("p.stl"));
    assert_eq!(edges(&t), Edges::default());
    assert_eq!(t.len() as u64, r["triangles"].as_u64().unwrap());
    let bad = run(&["tpms", "--memory", "lots", "-o", "x.stl"], dir.path());
    assert_eq!(bad.status.code(), Some(2));
    let bad = run(&["tpms", "--tile", "20", "-o", "x.stl"], dir.path());
    assert_eq!(bad.status.code(), Some(2));
}
