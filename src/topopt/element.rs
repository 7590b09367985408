//! Element stiffness (and conductivity) matrices, exactly as the published codes write them, so
//! latvox's compliance histories agree with theirs to rounding.
//!
//! - [`q4_plane_stress`]: the 4-node bilinear plane-stress square of the 88-line code
//!   (Andreassen et al. 2011), unit Young's modulus, DOF order (x, y) per node, nodes lower-left,
//!   lower-right, upper-right, upper-left.
//! - [`h8`]: the 8-node hexahedron of top3d (Liu & Tovar 2014), `lk_H8`, 24 × 24.
//! - [`q4_conduction`]: the bilinear heat-conduction square (unit conductivity), as in the
//!   heat-sink variant of the 99/88-line codes.

/// 8 × 8 plane-stress stiffness of a unit square element with E = 1, row-major.
pub fn q4_plane_stress(nu: f64) -> Vec<f64> {
    let a11 = [
        [12., 3., -6., -3.],
        [3., 12., 3., 0.],
        [-6., 3., 12., -3.],
        [-3., 0., -3., 12.],
    ];
    let a12 = [
        [-6., -3., 0., 3.],
        [-3., -6., -3., -6.],
        [0., -3., -6., 3.],
        [3., -6., 3., -6.],
    ];
    let b11 = [
        [-4., 3., -2., 9.],
        [3., -4., -9., 4.],
        [-2., -9., -4., -3.],
        [9., 4., -3., -4.],
    ];
    let b12 = [
        [2., -3., 4., -9.],
        [-3., 2., 9., -2.],
        [4., 9., 2., 3.],
        [-9., -2., 3., 2.],
    ];
    // [A11 A12; A12' A11] + nu [B11 B12; B12' B11]
    let block = |m11: &[[f64; 4]; 4], m12: &[[f64; 4]; 4], i: usize, j: usize| -> f64 {
        match (i / 4, j / 4) {
            (0, 0) | (1, 1) => m11[i % 4][j % 4],
            (0, 1) => m12[i % 4][j % 4],
            _ => m12[j % 4][i % 4],
        }
    };
    let mut ke = vec![0.0; 64];
    for i in 0..8 {
        for j in 0..8 {
            ke[i * 8 + j] = 1.0 / (1.0 - nu * nu) / 24.0
                * (block(&a11, &a12, i, j) + nu * block(&b11, &b12, i, j));
        }
    }
    ke
}

/// 4 × 4 conductivity matrix of a unit square with unit conductivity, row-major.
pub fn q4_conduction() -> Vec<f64> {
    let (a, b, c) = (2.0 / 3.0, -1.0 / 6.0, -1.0 / 3.0);
    vec![a, b, c, b, b, a, b, c, c, b, a, b, b, c, b, a]
}

/// 24 × 24 stiffness of a unit cube element with E = 1 (top3d's `lk_H8`), row-major.
pub fn h8(nu: f64) -> Vec<f64> {
    let a = [
        [
            32., 6., -8., 6., -6., 4., 3., -6., -10., 3., -3., -3., -4., -8.,
        ],
        [
            -48., 0., 0., -24., 24., 0., 0., 0., 12., -12., 0., 12., 12., 12.,
        ],
    ];
    let k: Vec<f64> = (0..14)
        .map(|i| (1.0 / 144.0) * (a[0][i] + a[1][i] * nu))
        .collect();
    let sub = |idx: [[usize; 6]; 6]| idx.map(|r| r.map(|i| k[i - 1]));
    let k1 = sub([
        [1, 2, 2, 3, 5, 5],
        [2, 1, 2, 4, 6, 7],
        [2, 2, 1, 4, 7, 6],
        [3, 4, 4, 1, 8, 8],
        [5, 6, 7, 8, 1, 2],
        [5, 7, 6, 8, 2, 1],
    ]);
    let k2 = sub([
        [9, 8, 12, 6, 4, 7],
        [8, 9, 12, 5, 3, 5],
        [10, 10, 13, 7, 4, 6],
        [6, 5, 11, 9, 2, 10],
        [4, 3, 5, 2, 9, 12],
        [11, 4, 6, 12, 10, 13],
    ]);
    let k3 = sub([
        [6, 7, 4, 9, 12, 8],
        [7, 6, 4, 10, 13, 10],
        [5, 5, 3, 8, 12, 9],
        [9, 10, 2, 6, 11, 5],
        [12, 13, 10, 11, 6, 4],
        [2, 12, 9, 4, 5, 3],
    ]);
    let k4 = sub([
        [14, 11, 11, 13, 10, 10],
        [11, 14, 11, 12, 9, 8],
        [11, 11, 14, 12, 8, 9],
        [13, 12, 12, 14, 7, 7],
        [10, 9, 8, 7, 14, 11],
        [10, 8, 9, 7, 11, 14],
    ]);
    let k5 = sub([
        [1, 2, 8, 3, 5, 4],
        [2, 1, 8, 4, 6, 11],
        [8, 8, 1, 5, 11, 6],
        [3, 4, 5, 1, 8, 2],
        [5, 6, 11, 8, 1, 8],
        [4, 11, 6, 2, 8, 1],
    ]);
    let k6 = sub([
        [14, 11, 7, 13, 10, 12],
        [11, 14, 7, 12, 9, 2],
        [7, 7, 14, 10, 2, 9],
        [13, 12, 10, 14, 7, 11],
        [10, 9, 2, 7, 14, 7],
        [12, 2, 9, 11, 7, 14],
    ]);
    // KE = 1/((nu+1)(1-2nu)) [K1 K2 K3 K4; K2' K5 K6 K3'; K3' K6 K5' K2'; K4 K3 K2 K1']
    type B = [[f64; 6]; 6];
    let layout: [[(&B, bool); 4]; 4] = [
        [(&k1, false), (&k2, false), (&k3, false), (&k4, false)],
        [(&k2, true), (&k5, false), (&k6, false), (&k3, true)],
        [(&k3, true), (&k6, false), (&k5, true), (&k2, true)],
        [(&k4, false), (&k3, false), (&k2, false), (&k1, true)],
    ];
    let s = 1.0 / ((nu + 1.0) * (1.0 - 2.0 * nu));
    let mut ke = vec![0.0; 576];
    for i in 0..24 {
        for j in 0..24 {
            let (m, t) = layout[i / 6][j / 6];
            let (r, c) = if t { (j % 6, i % 6) } else { (i % 6, j % 6) };
            ke[i * 24 + j] = s * m[r][c];
        }
    }
    ke
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rigid translations carry no strain energy, and the matrices are symmetric: a check of the
    /// transcription independent of the published numbers themselves.
    #[test]
    fn rigid_modes_and_symmetry() {
        for (ke, n, d) in [
            (q4_plane_stress(0.3), 8, 2),
            (h8(0.3), 24, 3),
            (q4_conduction(), 4, 1),
        ] {
            for i in 0..n {
                for j in 0..n {
                    assert!((ke[i * n + j] - ke[j * n + i]).abs() < 1e-14);
                }
            }
            for axis in 0..d {
                for i in 0..n {
                    let s: f64 = (0..n)
                        .filter(|j| j % d == axis)
                        .map(|j| ke[i * n + j])
                        .sum();
                    assert!(s.abs() < 1e-13, "row {i} axis {axis}: {s}");
                }
            }
        }
        // The H8 element of unit size with E = 1: trace from the closed form 2·Σ diag.
        let ke = h8(0.3);
        assert!(ke[0] > 0.0 && (0..24).all(|i| ke[i * 25] > 0.0));
    }
}
