//! latvox's `check` and `repair` on meshes made from bytes, CGAL and OpenVDB behind them: the body
//! of the `check_repair` fuzz target, and of the test that replays its corpus
//! (`tests/fuzz.rs`, which includes this file).
//!
//! The bytes: the vertex count (4 to 35), then three bytes per vertex — coordinates on a grid of
//! 0.5 mm steps, 0 to 4 mm, where coincident, collinear and coplanar corners are common — then
//! three bytes per facet, each a vertex index modulo the count (up to 64 facets).

use latvox::geom::Mesh;
use latvox::progress::Progress;
use latvox::repair::{repair, Remesh, RepairOptions};

/// The remesh voxel of `repair --solid`, mm (eighty across the grid's 4 mm).
pub const SOLID_VOXEL: f64 = 0.05;

/// The mesh the bytes describe, if they describe one with a facet.
pub fn mesh(data: &[u8]) -> Option<Mesh> {
    let (&n, rest) = data.split_first()?;
    let nv = 4 + n as usize % 32;
    if rest.len() < 3 * nv {
        return None;
    }
    let (vs, fs) = rest.split_at(3 * nv);
    let positions = vs.iter().map(|&b| (b % 9) as f32 * 0.5).collect();
    let indices: Vec<u32> = fs
        .chunks_exact(3)
        .take(64)
        .flatten()
        .map(|&b| (b as usize % nv) as u32)
        .collect();
    (!indices.is_empty()).then_some(Mesh { positions, indices })
}

/// `check`, CGAL's checks, `repair` and `repair --solid` on the mesh of `data`: none may panic,
/// abort or end in a backend error (exit 3); a refusal is exit 2; a solid that `repair --solid`
/// makes is valid by latvox's check and by CGAL's. Panics with the step that failed.
pub fn check_repair(data: &[u8]) {
    let Some(mesh) = mesh(data) else { return };
    let step = |what: &str, r: latvox::Result<()>| {
        if let Err(e) = r {
            panic!("{what}: {e}");
        }
    };
    let refused = |what: &str, e: latvox::Error| {
        assert_eq!(e.exit_code(), 2, "{what}: {e}");
    };
    step(
        "check",
        latvox::check::check(&mesh, None, &Default::default()).map(drop),
    );
    step(
        "CGAL's checks",
        latvox::verify::cgal::verify(&mesh, true).map(drop),
    );
    match repair(&mesh, &RepairOptions::default(), &Progress::hidden()) {
        Ok((m, _)) if m.triangle_count() > 0 => {
            let c = latvox::check::check(&m, None, &Default::default());
            step("check after repair", c.map(drop));
            let v = latvox::verify::cgal::verify(&m, true);
            step("CGAL's checks after repair", v.map(drop));
        }
        Ok(_) => {}
        Err(e) => refused("repair", e),
    }
    let solid = RepairOptions {
        solid: true,
        remesh: Some(Remesh::Voxel(SOLID_VOXEL)),
        ..Default::default()
    };
    match repair(&mesh, &solid, &Progress::hidden()) {
        Ok((m, _)) => {
            let m = latvox::io::weld::weld_indexed(&m.positions, &m.indices)
                .unwrap_or_else(|e| panic!("welding the solid: {e}"));
            let c = latvox::check::check(&m, None, &Default::default())
                .unwrap_or_else(|e| panic!("check of the solid: {e}"));
            assert!(
                c.defects().is_empty(),
                "repair --solid left {:?}",
                c.defects()
            );
            let v = latvox::verify::cgal::verify(&m, true)
                .unwrap_or_else(|e| panic!("CGAL's checks of the solid: {e}"));
            assert!(
                v.closed && !v.self_intersecting,
                "repair --solid: CGAL finds {v:?}"
            );
        }
        Err(e) => refused("repair --solid", e),
    }
}
