//! Where Rust calls C++: one bridge per library, [`vdb`] (OpenVDB, `cpp/vdb.h`) and [`cgal`]
//! (CGAL, `cpp/cgal.h`), each header implemented by a few small translation units, none of which
//! parses both libraries' headers. Nothing here is public, and no `cxx` type leaves this module:
//! safe wrappers live in `grid`, `verify::cgal`, `repair::cgal` and `lattice::voronoi::diagram`.

pub(crate) mod cgal;
pub(crate) mod vdb;

use crate::error::{Error, Result};

/// A C++ exception turned into the library's error, saying what was being done.
pub(crate) trait Backend<T> {
    fn backend(self, context: &'static str) -> Result<T>;
}

impl<T> Backend<T> for std::result::Result<T, cxx::Exception> {
    fn backend(self, context: &'static str) -> Result<T> {
        self.map_err(|e| Error::Backend {
            context,
            message: message(&e),
        })
    }
}

/// Longest C++ exception message passed on, in characters.
const MESSAGE_CHARS: usize = 300;

/// A C++ exception's message as one short line: runs of whitespace and control characters made
/// one space, at most [`MESSAGE_CHARS`] characters. (OpenVDB's message on a truncated `.vdb`
/// quotes a name whose length it read from the file: gigabytes of it.)
pub(crate) fn message(e: &cxx::Exception) -> String {
    let mut out = String::new();
    let mut chars = 0;
    let mut space = false;
    for (scanned, c) in e.what().chars().enumerate() {
        if scanned >= 16 * MESSAGE_CHARS {
            out.push('…');
            break;
        }
        if c.is_whitespace() || c.is_control() {
            space = !out.is_empty();
            continue;
        }
        if chars >= MESSAGE_CHARS {
            out.push('…');
            break;
        }
        if space {
            out.push(' ');
            chars += 1;
            space = false;
        }
        out.push(c);
        chars += 1;
    }
    out
}
