//! Values read from a `.vdb` file made by another tool (a density or fog volume): the grid
//! named `density`, or the file's first float grid, copied densely over its active voxels and
//! read trilinearly between the voxels' centres (as OpenVDB's BoxSampler reads it inside).

use crate::error::{Error, Result};
use crate::ffi::vdb::ffi;
use crate::field::nodes::Nodes;
use std::path::Path;

/// At most this many values are read densely (1 GiB of doubles).
const MAX_VALUES: u64 = 1 << 27;

/// The values of a `.vdb`'s float grid at its voxels' centres, mm, and the grid's name.
pub fn read_values(path: &Path) -> Result<(Nodes, String)> {
    let s = path
        .to_str()
        .ok_or_else(|| Error::invalid(format!("{}: path is not UTF-8", path.display())))?;
    if !path.is_file() {
        return Err(Error::invalid(format!(
            "cannot read {}: no such file",
            path.display()
        )));
    }
    let mut out = ffi::DenseValues::default();
    ffi::vdb_read_dense(s, MAX_VALUES, &mut out)
        .map_err(|e| Error::invalid(format!("{}: {}", path.display(), crate::ffi::message(&e))))?;
    let n = [0, 1, 2].map(|a| out.dims[a] as usize);
    let nodes = Nodes {
        origin: [out.origin[0], out.origin[1], out.origin[2]],
        step: [out.step; 3],
        n,
        values: out.values.iter().map(|&v| v as f64).collect(),
    };
    Ok((nodes, out.name))
}
