//! Exact Euclidean distance transform (Felzenszwalb & Huttenlocher's lower envelope of parabolas,
//! one axis at a time), in 2D and 3D: for every pixel, the distance to the nearest pixel centre
//! of the target set. Outside the grid counts as target when `outside_is_target` (the void beyond
//! the design domain).

use rayon::prelude::*;

const INF: f64 = 1e20;

/// Squared distances, in pixels², from each pixel to the nearest `target` pixel.
pub fn edt_squared(n: [usize; 3], target: &[bool], outside_is_target: bool) -> Vec<f64> {
    let [nx, ny, nz] = n;
    let mut f: Vec<f64> = target.iter().map(|&t| if t { 0.0 } else { INF }).collect();
    // Pad each line with one target sample at both ends when outside counts as target.
    let pass = |f: &mut Vec<f64>, len: usize, stride: usize, lines: Vec<usize>| {
        let results: Vec<(usize, Vec<f64>)> = lines
            .into_par_iter()
            .map(|start| {
                let pad = usize::from(outside_is_target);
                let mut line = vec![0.0; len + 2 * pad];
                for i in 0..len {
                    line[i + pad] = f[start + i * stride];
                }
                let d = envelope(&line);
                (start, d[pad..pad + len].to_vec())
            })
            .collect();
        for (start, d) in results {
            for (i, v) in d.into_iter().enumerate() {
                f[start + i * stride] = v;
            }
        }
    };
    let lines_x: Vec<usize> = (0..ny * nz).map(|r| r * nx).collect();
    pass(&mut f, nx, 1, lines_x);
    let lines_y: Vec<usize> = (0..nz)
        .flat_map(|z| (0..nx).map(move |x| z * nx * ny + x))
        .collect();
    pass(&mut f, ny, nx, lines_y);
    if nz > 1 {
        let lines_z: Vec<usize> = (0..nx * ny).collect();
        pass(&mut f, nz, nx * ny, lines_z);
    }
    f
}

/// 1D squared distance transform of sampled function `f` (Felzenszwalb & Huttenlocher 2012).
fn envelope(f: &[f64]) -> Vec<f64> {
    let n = f.len();
    let mut d = vec![INF; n];
    let mut v = vec![0usize; n];
    let mut z = vec![0.0f64; n + 1];
    let mut k = 0usize;
    let first = match f.iter().position(|&x| x < INF) {
        Some(i) => i,
        None => return d,
    };
    v[0] = first;
    z[0] = -INF;
    z[1] = INF;
    for q in first + 1..n {
        if f[q] >= INF {
            continue;
        }
        loop {
            let p = v[k];
            let s =
                ((f[q] + (q * q) as f64) - (f[p] + (p * p) as f64)) / (2.0 * (q as f64 - p as f64));
            if s <= z[k] && k > 0 {
                k -= 1;
                continue;
            }
            if s <= z[k] {
                // k == 0 and the new parabola dominates everywhere.
                v[0] = q;
                z[0] = -INF;
                z[1] = INF;
                break;
            }
            k += 1;
            v[k] = q;
            z[k] = s;
            z[k + 1] = INF;
            break;
        }
    }
    let mut k = 0;
    for (q, dq) in d.iter_mut().enumerate() {
        while z[k + 1] < q as f64 {
            k += 1;
        }
        let p = v[k];
        let dx = q as f64 - p as f64;
        *dq = dx * dx + f[p];
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_brute_force() {
        let n = [13, 9, 5];
        let target: Vec<bool> = (0..n[0] * n[1] * n[2])
            .map(|i| (i * 7919 % 23) == 0)
            .collect();
        for outside in [false, true] {
            let d = edt_squared(n, &target, outside);
            for z in 0..n[2] as i64 {
                for y in 0..n[1] as i64 {
                    for x in 0..n[0] as i64 {
                        let mut best = f64::INFINITY;
                        for (i, &t) in target.iter().enumerate() {
                            if t {
                                let (tx, ty, tz) = (
                                    (i % n[0]) as i64,
                                    ((i / n[0]) % n[1]) as i64,
                                    (i / (n[0] * n[1])) as i64,
                                );
                                best = best.min(
                                    ((x - tx).pow(2) + (y - ty).pow(2) + (z - tz).pow(2)) as f64,
                                );
                            }
                        }
                        if outside {
                            // Nearest point beyond the grid along any single axis.
                            for (c, m) in [(x, n[0]), (y, n[1]), (z, n[2])] {
                                best = best.min(((c + 1).min(m as i64 - c)).pow(2) as f64);
                            }
                        }
                        let i = ((z * n[1] as i64 + y) * n[0] as i64 + x) as usize;
                        assert_eq!(d[i], best, "at {x},{y},{z} outside={outside}");
                    }
                }
            }
        }
    }
}
