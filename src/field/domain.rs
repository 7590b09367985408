//! The box of a periodic part: its cells' size, its overall size and its lower corner (the
//! lattice's phase), given as whole cells, a size cut into cells, or a size filled with cells of
//! a given size (partial cells at the far sides).

use super::{Aabb, Vec3};
use crate::error::{Error, Result};

/// A periodic part's box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Domain {
    /// Cell size per axis, mm.
    pub cell: Vec3,
    /// Box size per axis, mm.
    pub size: Vec3,
    /// Lower corner of the box, mm.
    pub origin: Vec3,
}

impl Domain {
    /// Whole cells: `counts` cells of size `cell` per axis.
    pub fn from_cells(counts: [u32; 3], cell: Vec3, origin: Vec3) -> Result<Domain> {
        if counts.contains(&0) {
            return Err(Error::invalid("cell counts must be at least 1"));
        }
        Self::checked(cell, [0, 1, 2].map(|a| counts[a] as f64 * cell[a]), origin)
    }

    /// Overall dimensions `size` with `counts` cells per axis.
    pub fn from_size_and_cells(size: Vec3, counts: [u32; 3], origin: Vec3) -> Result<Domain> {
        if counts.contains(&0) {
            return Err(Error::invalid("cell counts must be at least 1"));
        }
        Self::checked([0, 1, 2].map(|a| size[a] / counts[a] as f64), size, origin)
    }

    /// Overall dimensions `size` filled with cells of size `cell` (partial cells at the far side).
    pub fn from_size_and_cell(size: Vec3, cell: Vec3, origin: Vec3) -> Result<Domain> {
        Self::checked(cell, size, origin)
    }

    fn checked(cell: Vec3, size: Vec3, origin: Vec3) -> Result<Domain> {
        for a in 0..3 {
            if !(cell[a] > 0.0 && cell[a].is_finite()) {
                return Err(Error::invalid(format!(
                    "cell size must be positive, got {}",
                    cell[a]
                )));
            }
            if !(size[a] > 0.0 && size[a].is_finite()) {
                return Err(Error::invalid(format!(
                    "box size must be positive, got {}",
                    size[a]
                )));
            }
            if !origin[a].is_finite() {
                return Err(Error::invalid("origin must be finite"));
            }
        }
        Ok(Domain { cell, size, origin })
    }

    /// The part's box, mm.
    pub fn bounds(&self) -> Aabb {
        Aabb {
            min: self.origin,
            max: [0, 1, 2].map(|a| self.origin[a] + self.size[a]),
        }
    }

    /// Cells per axis (fractional where the box ends inside a cell).
    pub fn counts(&self) -> Vec3 {
        [0, 1, 2].map(|a| self.size[a] / self.cell[a])
    }
}
