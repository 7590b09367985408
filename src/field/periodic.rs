//! Index-periodic sampling of periodic fields: where a cell spans a whole number of voxels,
//! a sample's place in its cell is taken from its index modulo that number, so that samples a
//! cell apart are bit-identical and every cell of a lattice meshes exactly alike (what copying
//! cells from a template relies on).

use super::Vec3;

/// Samples per cell along each axis where a cell of size `cell` holds a whole number of
/// samples of size `h` (0 on an axis where it does not), with `h`; `None` when no axis does.
pub fn samples_per_cell(cell: Vec3, h: f64) -> Option<([u32; 3], f64)> {
    let p = [0, 1, 2].map(|a| {
        let n = (cell[a] / h).round();
        if n >= 1.0 && (cell[a] / h - n).abs() < 1e-9 * n {
            n as u32
        } else {
            0
        }
    });
    (p != [0; 3]).then_some((p, h))
}

/// The places in their cell, as fractions of the cell (`[0, 1)` when periodic; unwrapped
/// otherwise), of the 8 samples `start + i·h` along `axis` of a lattice whose cells of size
/// `cell` start at `phase`. Where `periodic` (from [`samples_per_cell`]) says a cell holds a
/// whole number of samples of this `h`, and the samples sit at `phase + (j + ½)·h`, each is
/// `(j mod n + ½) / n`.
pub fn block_axis(
    periodic: Option<([u32; 3], f64)>,
    phase: f64,
    cell: f64,
    start: f64,
    h: f64,
    axis: usize,
) -> [f64; 8] {
    let index = periodic.and_then(|(n, hp)| {
        let j = (start - phase) / h - 0.5;
        let r = j.round();
        (hp == h && n[axis] > 0 && (j - r).abs() < 1e-6).then_some((r as i64, n[axis] as i64))
    });
    std::array::from_fn(|i| match index {
        Some((j0, n)) => ((j0 + i as i64).rem_euclid(n) as f64 + 0.5) / n as f64,
        None => (start + h * i as f64 - phase) / cell,
    })
}
