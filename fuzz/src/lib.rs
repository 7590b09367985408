//! latvox's mesh readers, compiled from latvox's own source files for fuzzing. Only the stages
//! the readers need are included (errors, geometry, io, fields), so the fuzz build never
//! compiles the C++ bridges. `check` holds the invariants every target
//! asserts on a successful parse.
#![allow(dead_code, unused_imports)]

#[path = "../../src/error.rs"]
pub mod error;
#[path = "../../src/geom/mod.rs"]
pub mod geom;
#[path = "../../src/field/mod.rs"]
pub mod field;
#[path = "../../src/io/mod.rs"]
pub mod io;


pub use error::{Error, Result};

/// Parses `data` as `format`; on success, every index must name a vertex, every coordinate
/// must be finite, and tolerance welding must keep that true.
pub fn check(data: &[u8], format: io::Format) {
    if let Ok(p) = io::parse(data, format) {
        let m = p.mesh;
        let nv = m.vertex_count();
        assert!(m.indices.len() % 3 == 0 && m.positions.len() % 3 == 0);
        assert!(m.indices.iter().all(|&i| (i as usize) < nv));
        assert!(m.positions.iter().all(|x| x.is_finite()));
        if let Some(n) = &p.normals {
            assert_eq!(n.len(), m.triangle_count());
        }
        let mut welded = m.clone();
        io::weld::weld_tolerance(&mut welded, 1e-3);
        assert_eq!(welded.indices.len(), m.indices.len());
        assert!(welded.indices.iter().all(|&i| (i as usize) < welded.vertex_count()));
    }
}
