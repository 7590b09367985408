//! Periodic Voronoi foams: seeds in a cell that tiles space, so that one cell of the foam,
//! random inside, repeats without a seam.
//!
//! The seeds are Poisson-disk points of the cell measured with their nearest copies
//! ([`super::seeds::poisson_periodic`]). Their diagram is the diagram of the seeds and their 26
//! copies in the neighbouring cells (CGAL's, as for any foam): every Voronoi vertex, edge and
//! face that reaches into the cell is that of the infinite periodic set of points as long as
//! the cell is at least two spacings wide (a Delaunay sphere of a Poisson-disk set is at most
//! about a spacing across). A [`Foam`] made on the cell from those copies is then periodic
//! itself: its model, pore sizes and statistics are the tiling's.
//!
//! A periodic net is a strut lattice: [`net_cell`] gives its struts as a unit cell, each edge
//! once, so that the strut machinery (instancing, grading, drawing, beams, homogenisation)
//! takes it as it takes any cell.

use super::foam::{Foam, FoamStats, Structure};
use super::seeds::{images, poisson_periodic, regularise, wrap};
use crate::error::{Error, Result};
use crate::geom::{Aabb, Vec3};
use crate::lattice::strut::UnitCell;
use kiddo::{KdTree, SquaredEuclidean};

/// The fewest spacings across a periodic cell.
pub const MIN_SPACINGS: f64 = 2.0;

/// Most seeds a periodic cell may hold.
pub const MAX_CELL_SEEDS: usize = 4000;

/// The seeds of a cell with their copies in the 26 neighbouring cells, the cell's own first.
pub fn with_copies(seeds: &[Vec3], cell: &Aabb) -> Vec<Vec3> {
    let size = cell.size();
    let mut out = Vec::with_capacity(27 * seeds.len());
    for n in 0..27 {
        out.extend(
            seeds
                .iter()
                .map(|&s| images(s, size).nth(n).expect("27 images")),
        );
    }
    out
}

/// Refuses a periodic cell narrower than [`MIN_SPACINGS`] spacings or holding more than
/// [`MAX_CELL_SEEDS`] seeds.
pub fn check_cell(size: Vec3, spacing: f64) -> Result<()> {
    let period = size.iter().cloned().fold(f64::INFINITY, f64::min);
    if !(period > 0.0 && size.iter().all(|x| x.is_finite())) {
        return Err(Error::setting(
            "periodic",
            format!("the periodic cell must be a positive length in mm, got {period}"),
        ));
    }
    if period < MIN_SPACINGS * spacing {
        return Err(Error::setting(
            "periodic",
            format!(
                "a periodic cell of {period} mm is under {MIN_SPACINGS} spacings of {spacing} mm: make the cell {} mm or more, or the spacing smaller",
                MIN_SPACINGS * spacing
            ),
        ));
    }
    let n = size.iter().product::<f64>() / spacing.powi(3);
    if n > MAX_CELL_SEEDS as f64 {
        return Err(Error::setting(
            "periodic",
            format!(
                "a periodic cell of {period} mm holds about {n:.0} seeds of spacing {spacing} mm, more than {MAX_CELL_SEEDS}: make the cell up to {:.1} mm (it repeats through any box) or the spacing larger",
                spacing * (MAX_CELL_SEEDS as f64).cbrt()
            ),
        ));
    }
    Ok(())
}

/// A random periodic net as a unit cell: Poisson-disk seeds at `spacing` in a cell of `size`
/// mm, moved `regularity` of the way toward the body-centred cubic lattice, their diagram's
/// edges shorter than `merge` mm merged; with the foam's statistics.
pub fn random_net_cell(
    size: Vec3,
    spacing: f64,
    seed: u64,
    regularity: f64,
    merge: f64,
) -> Result<(UnitCell, FoamStats)> {
    check_cell(size, spacing)?;
    let cell = Aabb {
        min: [0.0; 3],
        max: size,
    };
    let points = poisson_periodic(&cell, spacing, seed);
    let points = regularise(&points, &cell, spacing, regularity, seed, true);
    let foam = Foam::new(
        Structure::Net,
        cell,
        with_copies(&points, &cell),
        merge,
        spacing,
    )?
    .repeating(size);
    Ok((net_cell(&foam)?, foam.stats))
}

/// The struts of a periodic net (a [`Foam`] made on its cell from the seeds and their copies)
/// as a unit cell: each Voronoi edge once, its ends in unit-cell coordinates.
pub fn net_cell(foam: &Foam) -> Result<UnitCell> {
    let cell = foam.bounds;
    let size = cell.size();
    let d = &foam.diagram;
    // Every edge whose middle is in the cell (or on its faces: the strut cell keeps one of
    // each set of translates).
    let near = cell.grown(1e-9 * size.iter().cloned().fold(0.0, f64::max));
    let tol = 1e-6 * size.iter().cloned().fold(f64::INFINITY, f64::min);
    // Nodes by their place in the cell: a vertex and its translates are one node.
    let mut places: Vec<Vec3> = Vec::new();
    let mut tree: KdTree<f64, 3> = KdTree::new();
    let mut node_of = |p: Vec3| -> Vec3 {
        let w = wrap(p, &cell);
        let found = images(w, size).find_map(|q| {
            (tree.size() > 0)
                .then(|| tree.nearest_one::<SquaredEuclidean>(&q))
                .filter(|n| n.distance <= tol * tol)
                .map(|n| (n.item as usize, q))
        });
        let (i, q) = found.unwrap_or_else(|| {
            tree.add(&w, places.len() as u64);
            places.push(w);
            (places.len() - 1, w)
        });
        // `p` is the node moved by whole cells (the image `q` of `w` matched the node).
        let base = places[i];
        let shift = [0, 1, 2].map(|k| ((p[k] - w[k] + q[k] - base[k]) / size[k]).round());
        [0, 1, 2].map(|k| (base[k] - cell.min[k]) / size[k] + shift[k])
    };
    let mut segments = Vec::new();
    for &[a, b] in &d.edges {
        let (p, q) = (d.vertices[a as usize], d.vertices[b as usize]);
        let mid = [0, 1, 2].map(|k| 0.5 * (p[k] + q[k]));
        if near.contains(mid) {
            segments.push([node_of(p), node_of(q)]);
        }
    }
    let unit = UnitCell::from_segments(&segments).canonical();
    match unit.separate_lattices() {
        Some(1) => Ok(unit),
        _ => Err(Error::invalid(
            "the periodic foam's edges do not join into one lattice: give a larger --periodic cell",
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A periodic net's cell has the edges of the diagram of the infinite periodic seed set:
    /// about thirteen edges per seed (a cell of about 15 faces of about 5 edges, each edge
    /// shared by three cells), joined into one lattice.
    #[test]
    fn a_periodic_net_is_one_lattice_with_the_foams_edges() {
        let cell = Aabb {
            min: [1.0, -2.0, 0.5],
            max: [13.0, 10.0, 12.5],
        };
        let seeds = poisson_periodic(&cell, 3.0, 5);
        assert!(seeds
            .iter()
            .all(|s| (0..3).all(|k| s[k] >= cell.min[k] && s[k] < cell.max[k])));
        let n = seeds.len() as f64;
        assert!((n - 64.0).abs() < 8.0, "{n} seeds in a cell of 4 spacings");
        let foam = Foam::new(Structure::Net, cell, with_copies(&seeds, &cell), 1e-6, 3.0).unwrap();
        let unit = net_cell(&foam).unwrap();
        let per_seed = unit.struts.len() as f64 / n;
        assert!(
            (11.0..15.0).contains(&per_seed),
            "{per_seed} struts per seed"
        );
        // Every node has at least three struts (four in general position), counted over the
        // translates: nodes are places in the cell.
        let mut degree = std::collections::HashMap::new();
        for &[i, j] in &unit.struts {
            for k in [i, j] {
                let key =
                    unit.nodes[k].map(|x| ((x.rem_euclid(1.0)) * 1e6).round() as i64 % 1_000_000);
                *degree.entry(key).or_insert(0) += 1;
            }
        }
        assert!(
            degree.values().all(|&d| d >= 3),
            "a node with fewer than 3 struts"
        );
    }
}
