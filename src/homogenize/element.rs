//! The trilinear hexahedron (8 nodes, 24 displacements) of an isotropic solid, on a box of any
//! edge lengths, integrated by 2 × 2 × 2 Gauss points (exact for a box). Node `a` sits at the
//! corner `(a & 1, a >> 1 & 1, a >> 2 & 1)`; strains are in Voigt order
//! `[εxx, εyy, εzz, γyz, γxz, γxy]` with engineering shears (γ = 2ε).

// Index loops read as the formulas they transcribe.
#![allow(clippy::needless_range_loop)]

/// Stiffness `Ke` of a box with edges `h` of a solid with Lamé constants `lambda`, `mu`,
/// row-major 24 × 24.
pub fn stiffness(h: [f64; 3], lambda: f64, mu: f64) -> [f64; 576] {
    let d = elasticity(lambda, mu);
    let g = 1.0 / 3f64.sqrt();
    let det = h[0] * h[1] * h[2] / 8.0;
    let mut ke = [0.0; 576];
    for gp in 0..8 {
        let xi = [0, 1, 2].map(|a| if gp >> a & 1 == 1 { g } else { -g });
        let b = strain_matrix(xi, h);
        // Ke += Bᵀ D B det.
        let mut db = [[0.0; 24]; 6];
        for i in 0..6 {
            for j in 0..24 {
                db[i][j] = (0..6).map(|k| d[i][k] * b[k][j]).sum();
            }
        }
        for i in 0..24 {
            for j in 0..24 {
                ke[i * 24 + j] += det * (0..6).map(|k| b[k][i] * db[k][j]).sum::<f64>();
            }
        }
    }
    ke
}

/// The 6 × 6 elasticity matrix of an isotropic solid (Voigt order, engineering shears).
pub fn elasticity(lambda: f64, mu: f64) -> [[f64; 6]; 6] {
    let mut d = [[0.0; 6]; 6];
    for i in 0..3 {
        for j in 0..3 {
            d[i][j] = lambda + if i == j { 2.0 * mu } else { 0.0 };
        }
        d[i + 3][i + 3] = mu;
    }
    d
}

/// The strain–displacement matrix `B` (6 × 24) at the reference point `xi` ∈ [−1, 1]³ of a box
/// with edges `h`.
fn strain_matrix(xi: [f64; 3], h: [f64; 3]) -> [[f64; 24]; 6] {
    let mut b = [[0.0; 24]; 6];
    for a in 0..8 {
        let s = [0, 1, 2].map(|k| if a >> k & 1 == 1 { 1.0 } else { -1.0 });
        let n = [0, 1, 2].map(|k| 0.5 * (1.0 + s[k] * xi[k]));
        // ∂N/∂x_k = s_k/2 · Π_{l≠k} n_l · 2/h_k.
        let dn = [0, 1, 2].map(|k| {
            let others: f64 = (0..3).filter(|&l| l != k).map(|l| n[l]).product();
            s[k] * others / h[k]
        });
        let c = 3 * a;
        b[0][c] = dn[0];
        b[1][c + 1] = dn[1];
        b[2][c + 2] = dn[2];
        b[3][c + 1] = dn[2];
        b[3][c + 2] = dn[1];
        b[4][c] = dn[2];
        b[4][c + 2] = dn[0];
        b[5][c] = dn[1];
        b[5][c + 1] = dn[0];
    }
    b
}

/// The nodal displacements of a box with edges `h` under the unit strain of Voigt component
/// `case` (`u = ε·x` from the box's lower corner): 24 values.
pub fn unit_strain(case: usize, h: [f64; 3]) -> [f64; 24] {
    let mut e = [[0.0; 3]; 3];
    match case {
        0..=2 => e[case][case] = 1.0,
        _ => {
            // γ = 1: ε_ij = ε_ji = ½ for (yz, xz, xy).
            let (i, j) = [(1, 2), (0, 2), (0, 1)][case - 3];
            e[i][j] = 0.5;
            e[j][i] = 0.5;
        }
    }
    let mut u = [0.0; 24];
    for a in 0..8 {
        let x = [0, 1, 2].map(|k| if a >> k & 1 == 1 { h[k] } else { 0.0 });
        for i in 0..3 {
            u[3 * a + i] = (0..3).map(|j| e[i][j] * x[j]).sum();
        }
    }
    u
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Under a unit strain the element's strain energy is `½·Dᵢᵢ·V`: the element reproduces a
    /// uniform strain exactly, and its rigid translations carry no energy.
    #[test]
    fn uniform_strains_carry_the_materials_energy() {
        let h = [0.5, 0.75, 1.25];
        let (lambda, mu) = (115.4, 79.6);
        let ke = stiffness(h, lambda, mu);
        let d = elasticity(lambda, mu);
        let v = h[0] * h[1] * h[2];
        for i in 0..6 {
            for j in 0..6 {
                let (ui, uj) = (unit_strain(i, h), unit_strain(j, h));
                let e: f64 = (0..24)
                    .map(|r| ui[r] * (0..24).map(|c| ke[r * 24 + c] * uj[c]).sum::<f64>())
                    .sum();
                assert!((e - d[i][j] * v).abs() < 1e-9 * d[0][0] * v, "{i} {j}: {e}");
            }
        }
        for r in 0..24 {
            for axis in 0..3 {
                let s: f64 = (0..8).map(|b| ke[r * 24 + 3 * b + axis]).sum();
                assert!(s.abs() < 1e-9 * d[0][0]);
            }
            for c in 0..24 {
                assert!((ke[r * 24 + c] - ke[c * 24 + r]).abs() < 1e-9 * d[0][0]);
            }
        }
    }
}
