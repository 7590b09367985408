//! The lattice as beams: every translate of every strut of the cell that reaches into the box,
//! its ends shared between beams where they coincide — what the 3MF Beam Lattice extension
//! stores instead of triangles. The beams are not cut: the box clips them (a clipping mesh),
//! so a strut the box cuts ends exactly on the box, as in the meshed part.

use super::lattice::StrutLattice;
use crate::field::{Aabb, Vec3};
use crate::io::threemf::BeamModel;
use std::collections::HashMap;

/// Ends closer than this (mm) are one vertex.
const WELD: f64 = 1e-7;

/// The beams of `lattice` that reach into its box (within their radius).
pub fn beams(lattice: &StrutLattice) -> BeamModel {
    let size = lattice.size;
    let b = lattice.bounds;
    let segments = lattice.cell.segments(size);
    let reach = segments
        .iter()
        .map(|(_, f)| f[0].max(f[1]))
        .fold(0.0, f64::max)
        * lattice.radius;
    // A canonical strut's midpoint lies in its cell, and no strut is longer than a few cells:
    // cells from two below the box to one above it hold every strut that can reach in.
    let range = |a: usize| {
        let lo = ((b.min[a] - lattice.phase[a]) / size[a]).floor() as i64 - 2;
        let hi = ((b.max[a] - lattice.phase[a]) / size[a]).ceil() as i64 + 1;
        lo..=hi
    };
    let mut model = BeamModel {
        radius: lattice.radius,
        min_length: 1e-4,
        clip: Some(b),
        ..BeamModel::default()
    };
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut vertex = |p: Vec3, model: &mut BeamModel| -> u32 {
        let key = p.map(|x| (x / WELD).round() as i64);
        *index.entry(key).or_insert_with(|| {
            model.vertices.push(p);
            (model.vertices.len() - 1) as u32
        })
    };
    for i in range(0) {
        for j in range(1) {
            for k in range(2) {
                let corner = [0, 1, 2].map(|a| lattice.phase[a] + [i, j, k][a] as f64 * size[a]);
                for (s, ([p, q], f)) in segments.iter().enumerate() {
                    let p = [0, 1, 2].map(|a| corner[a] + p[a]);
                    let q = [0, 1, 2].map(|a| corner[a] + q[a]);
                    if segment_box_distance(p, q, &b) > reach {
                        continue;
                    }
                    let v = [vertex(p, &mut model), vertex(q, &mut model)];
                    model.beams.push((v, f.map(|x| x * lattice.radius)));
                    model.sets.push(s as u32);
                }
            }
        }
    }
    model.set_names = lattice
        .cell
        .struts
        .iter()
        .enumerate()
        .map(|(s, &[i, j])| {
            let n = |p: Vec3| p.map(|x| format!("{x}")).join(" ");
            format!(
                "strut {s}: ({}) to ({})",
                n(lattice.cell.nodes[i]),
                n(lattice.cell.nodes[j])
            )
        })
        .collect();
    model
}

/// Distance from the segment `pq` to the box (0 when they meet): the distance to a box is
/// convex along a line, so a golden-section search over the segment finds its minimum.
pub fn segment_box_distance(p: Vec3, q: Vec3, b: &Aabb) -> f64 {
    let at = |t: f64| {
        let x = [0, 1, 2].map(|a| p[a] + t * (q[a] - p[a]));
        (0..3)
            .map(|a| (b.min[a] - x[a]).max(x[a] - b.max[a]).max(0.0).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..60 {
        let (a, c) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if at(a) <= at(c) {
            hi = c;
        } else {
            lo = a;
        }
    }
    at(0.5 * (lo + hi)).min(at(0.0)).min(at(1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::strut::UnitCell;
    use std::sync::Arc;

    #[test]
    fn simple_cubic_beams_in_whole_cells_are_counted_by_hand() {
        // 2×2×2 cells of sc: the nodes form a 3×3×3 grid inside the box (each beam in it once),
        // and beams from the nodes just outside reach in by their radius: 3 axes × 3 × 3 lines
        // × (2 inside + 2 poking in) beams.
        let lattice = StrutLattice {
            cell: Arc::new(UnitCell::built_in("sc").unwrap()),
            size: [5.0; 3],
            radius: 0.5,
            blend: 0.0,
            bounds: Aabb {
                min: [0.0; 3],
                max: [10.0; 3],
            },
            phase: [0.0; 3],
        };
        let m = beams(&lattice);
        assert_eq!(m.beams.len(), 3 * 9 * 4);
        assert!(m
            .beams
            .iter()
            .all(|(v, r)| v[0] != v[1] && r == &[0.5, 0.5]));
        // 27 nodes inside, 6 faces × 9 outside.
        assert_eq!(m.vertices.len(), 27 + 54);
        assert_eq!(m.sets.len(), m.beams.len());
        assert_eq!(m.set_names.len(), 3);
    }

    #[test]
    fn segment_box_distances() {
        let b = Aabb {
            min: [0.0; 3],
            max: [1.0; 3],
        };
        assert_eq!(
            segment_box_distance([-1.0, 0.5, 0.5], [2.0, 0.5, 0.5], &b),
            0.0
        );
        let d = segment_box_distance([2.0, 2.0, 0.5], [3.0, 2.0, 0.5], &b);
        assert!((d - 2f64.sqrt()).abs() < 1e-9, "{d}");
        let d = segment_box_distance([-1.0, 2.0, 0.5], [3.0, 2.0, 0.5], &b);
        assert!((d - 1.0).abs() < 1e-9, "{d}");
    }
}
