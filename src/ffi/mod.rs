//! Where Rust calls C++: one bridge per library, [`vdb`] (OpenVDB, `cpp/vdb.h`) and [`cgal`]
//! (CGAL, `cpp/cgal.h`), each header implemented by a few small translation units, none of which
//! parses both libraries' headers. Nothing here is public, and no `cxx` type leaves this module:
//! safe wrappers live in `grid`, `verify::cgal` and `repair::cgal`.

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
            message: e.what().to_string(),
        })
    }
}
