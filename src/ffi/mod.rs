//! Where Rust calls C++: [`cgal`] is CGAL's one bridge (`cpp/cgal.h`), implemented by small
//! translation units of its own; OpenVDB is reached through [`vdb`], [`vdb_filter`] and
//! [`vdb_remesh`]. Nothing here is public; safe wrappers live in `grid`, `verify` and `repair`.

pub(crate) mod cgal;
pub(crate) mod vdb;
pub(crate) mod vdb_filter;
pub(crate) mod vdb_remesh;

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
