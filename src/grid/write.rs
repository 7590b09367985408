//! A grid written as an OpenVDB `.vdb` file.

use super::Grid;
use crate::error::{Error, Result};
use crate::ffi::vdb::ffi;
use crate::ffi::Backend;

impl Grid {
    /// Writes the grid as a `.vdb` file.
    pub fn write_vdb(&self, path: &std::path::Path) -> Result<()> {
        let s = path
            .to_str()
            .ok_or_else(|| Error::invalid(format!("{}: path is not UTF-8", path.display())))?;
        ffi::vdb_write(&self.inner, s).backend("writing the .vdb file")
    }
}
