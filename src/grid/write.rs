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

/// Writes several grids to one `.vdb` file, each under its name (`sdf`, `distance`, a
/// material's name), as OpenVDB's tools and its Python module list them.
pub fn write_vdb_grids(path: &std::path::Path, grids: &[(&str, &Grid)]) -> Result<()> {
    let s = path
        .to_str()
        .ok_or_else(|| Error::invalid(format!("{}: path is not UTF-8", path.display())))?;
    let mut file = ffi::vdb_file_new();
    for (name, g) in grids {
        ffi::vdb_file_add(file.pin_mut(), &g.inner, name);
    }
    ffi::vdb_file_write(&file, s).backend("writing the .vdb file")
}
