//! What designers read off an elasticity tensor: the engineering constants (Young's and shear
//! moduli, Poisson's ratios from the compliance `S = C⁻¹`), Zener's anisotropy ratio and the
//! directional Young's modulus `E(d) = 1 / (σ(d)ᵀ S σ(d))` for a uniaxial unit stress along `d`.
//! Voigt order `xx, yy, zz, yz, xz, xy` with engineering shears throughout.

// Index loops read as the formulas they transcribe.
#![allow(clippy::needless_range_loop)]

use crate::error::{Error, Result};

/// A 6 × 6 matrix in Voigt order.
pub type Voigt = [[f64; 6]; 6];

/// The engineering constants of a tensor.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Constants {
    /// Young's moduli along x, y, z.
    pub young: [f64; 3],
    /// Shear moduli G_yz, G_xz, G_xy.
    pub shear: [f64; 3],
    /// Poisson's ratios ν_ij = −S_ij/S_ii (strain along j under stress along i): rows i = x, y, z.
    pub poisson: [[f64; 3]; 3],
    /// Zener's ratio 2·C44/(C11 − C12) from the axes' means (1: isotropic, for cubic symmetry).
    pub zener: f64,
    /// Bulk modulus under hydrostatic stress, 1/Σ_{i,j≤3} S_ij.
    pub bulk: f64,
    /// The stiffest and softest directions found and their Young's moduli.
    pub young_max: (f64, [f64; 3]),
    /// See `young_max`.
    pub young_min: (f64, [f64; 3]),
    /// Young's modulus averaged over all directions.
    pub young_mean: f64,
    /// Young's modulus along [110] and [111].
    pub young_110: f64,
    /// See `young_110`.
    pub young_111: f64,
}

/// The inverse of a symmetric positive definite 6 × 6 matrix by its Cholesky factor; an error
/// where a pivot falls below `floor` (the matrix is not definite for the purpose: some strain
/// finds less than `floor` in it).
pub fn invert(c: &Voigt, floor: f64) -> Result<Voigt> {
    let mut l = [[0.0; 6]; 6];
    for j in 0..6 {
        let d = c[j][j] - (0..j).map(|k| l[j][k] * l[j][k]).sum::<f64>();
        if d.is_nan() || d <= floor {
            return Err(Error::invalid(
                "the stiffness is not positive definite: some strain meets no resistance",
            ));
        }
        l[j][j] = d.sqrt();
        for i in j + 1..6 {
            l[i][j] = (c[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>()) / l[j][j];
        }
    }
    let mut inv = [[0.0; 6]; 6];
    for col in 0..6 {
        // L y = e_col, then Lᵀ x = y.
        let mut y = [0.0; 6];
        for i in 0..6 {
            let e = if i == col { 1.0 } else { 0.0 };
            y[i] = (e - (0..i).map(|k| l[i][k] * y[k]).sum::<f64>()) / l[i][i];
        }
        let mut x = [0.0; 6];
        for i in (0..6).rev() {
            x[i] = (y[i] - (i + 1..6).map(|k| l[k][i] * x[k]).sum::<f64>()) / l[i][i];
        }
        for i in 0..6 {
            inv[i][col] = x[i];
        }
    }
    Ok(inv)
}

/// Young's modulus along the unit direction `d` from the compliance `s`.
pub fn young_along(s: &Voigt, d: [f64; 3]) -> f64 {
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let d = d.map(|x| x / n);
    let sigma = [
        d[0] * d[0],
        d[1] * d[1],
        d[2] * d[2],
        d[1] * d[2],
        d[0] * d[2],
        d[0] * d[1],
    ];
    let mut e = 0.0;
    for i in 0..6 {
        for j in 0..6 {
            e += sigma[i] * s[i][j] * sigma[j];
        }
    }
    1.0 / e
}

/// `count` directions spread evenly over the sphere (a Fibonacci lattice).
pub fn directions(count: usize) -> Vec<[f64; 3]> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..count)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / count as f64;
            let r = (1.0 - z * z).sqrt();
            let phi = golden * i as f64;
            [r * phi.cos(), r * phi.sin(), z]
        })
        .collect()
}

impl Constants {
    /// The constants of the stiffness `c` (with its compliance `s`).
    pub fn of(c: &Voigt, s: &Voigt) -> Constants {
        let mut poisson = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                if i != j {
                    poisson[i][j] = -s[i][j] / s[i][i];
                }
            }
        }
        let mean = |k: &[(usize, usize)]| k.iter().map(|&(i, j)| c[i][j]).sum::<f64>() / 3.0;
        let (c11, c12, c44) = (
            mean(&[(0, 0), (1, 1), (2, 2)]),
            mean(&[(0, 1), (0, 2), (1, 2)]),
            mean(&[(3, 3), (4, 4), (5, 5)]),
        );
        let mut young_max = (f64::NEG_INFINITY, [0.0; 3]);
        let mut young_min = (f64::INFINITY, [0.0; 3]);
        // The cube's 13 directions of symmetry (axes, face and body diagonals) besides the
        // spread, where cells' extremes often lie.
        let symmetric = [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0, 0.0],
            [1.0, -1.0, 0.0],
            [1.0, 0.0, 1.0],
            [1.0, 0.0, -1.0],
            [0.0, 1.0, 1.0],
            [0.0, 1.0, -1.0],
            [1.0, 1.0, 1.0],
            [1.0, 1.0, -1.0],
            [1.0, -1.0, 1.0],
            [-1.0, 1.0, 1.0],
        ]
        .map(|d: [f64; 3]| {
            let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            d.map(|x| x / n)
        });
        let spread = directions(4000);
        let young_mean =
            spread.iter().map(|d| young_along(s, *d)).sum::<f64>() / spread.len() as f64;
        for d in symmetric.into_iter().chain(spread) {
            let e = young_along(s, d);
            if e > young_max.0 * (1.0 + 1e-9) {
                young_max = (e, d);
            }
            if e < young_min.0 * (1.0 - 1e-9) {
                young_min = (e, d);
            }
        }
        let bulk = 1.0
            / (0..3)
                .flat_map(|i| (0..3).map(move |j| (i, j)))
                .map(|(i, j)| s[i][j])
                .sum::<f64>();
        Constants {
            young: [0, 1, 2].map(|i| 1.0 / s[i][i]),
            shear: [3, 4, 5].map(|i| 1.0 / s[i][i]),
            poisson,
            zener: 2.0 * c44 / (c11 - c12),
            bulk,
            young_max,
            young_min,
            young_mean,
            young_110: young_along(s, [1.0, 1.0, 0.0]),
            young_111: young_along(s, [1.0, 1.0, 1.0]),
        }
    }
}

/// The Lamé constants of Young's modulus `e` and Poisson's ratio `nu`.
pub fn lame(e: f64, nu: f64) -> (f64, f64) {
    (
        e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
        e / (2.0 * (1.0 + nu)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::homogenize::element::elasticity;

    #[test]
    fn an_isotropic_solid_has_its_own_constants_in_every_direction() {
        let (e, nu) = (206.31, 0.2959);
        let (l, m) = lame(e, nu);
        let c = elasticity(l, m);
        let s = invert(&c, 1e-12).unwrap();
        let k = Constants::of(&c, &s);
        for a in 0..3 {
            assert!((k.young[a] - e).abs() < 1e-9 * e);
            assert!((k.shear[a] - e / (2.0 * (1.0 + nu))).abs() < 1e-9 * e);
        }
        assert!((k.poisson[0][1] - nu).abs() < 1e-12);
        assert!((k.zener - 1.0).abs() < 1e-12);
        assert!((k.young_max.0 - k.young_min.0).abs() < 1e-9 * e);
        assert!((k.bulk - e / (3.0 * (1.0 - 2.0 * nu))).abs() < 1e-9 * e);
    }
}
