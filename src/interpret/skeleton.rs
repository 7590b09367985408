//! Skeleton of a 2D solid (Liu et al. 2018, step 1.2): Zhang–Suen thinning to a one-pixel medial
//! curve, then spur pruning, as MATLAB's `bwmorph(…, 'skel')` and `'spur'` do in that paper.
//!
//! Thinning peels boundary pixels in two alternating sub-iterations, never breaking connectivity
//! (a pixel goes only if its neighbours form a single run). Only pixels next to a deletion can
//! change, so each pass visits a shrinking candidate list, not the whole image.
//!
//! Pruning: a terminal branch (endpoint to junction) is a spur — an artefact of a corner, not a
//! member — when it is very short, or when the inscribed radius falls steadily along it towards
//! its tip (a convex corner of interior angle θ makes the radius fall at `sin(θ/2)` per unit
//! length; a member of constant width keeps it). Removing a spur can expose a new terminal
//! branch, so pruning repeats a few rounds.

/// Neighbour offsets P2..P9 (N, NE, E, SE, S, SW, W, NW) with y up.
const RING: [(isize, isize); 8] = [
    (0, 1),
    (1, 1),
    (1, 0),
    (1, -1),
    (0, -1),
    (-1, -1),
    (-1, 0),
    (-1, 1),
];

struct Img<'a> {
    nx: usize,
    ny: usize,
    on: &'a [bool],
}

impl Img<'_> {
    fn get(&self, x: isize, y: isize) -> bool {
        x >= 0
            && y >= 0
            && (x as usize) < self.nx
            && (y as usize) < self.ny
            && self.on[y as usize * self.nx + x as usize]
    }

    fn ring(&self, i: usize) -> [bool; 8] {
        let (x, y) = ((i % self.nx) as isize, (i / self.nx) as isize);
        RING.map(|(dx, dy)| self.get(x + dx, y + dy))
    }
}

/// Number of off→on transitions around the ring (the connectivity number A(p)).
fn transitions(p: &[bool; 8]) -> usize {
    (0..8).filter(|&k| !p[k] && p[(k + 1) % 8]).count()
}

/// Zhang–Suen thinning of `mask` (`nx × ny`, x fastest): the skeleton pixels' indices.
// The deletion conditions are written as in Zhang & Suen's paper.
#[allow(clippy::nonminimal_bool)]
pub fn thin(nx: usize, ny: usize, mask: &[bool]) -> Vec<bool> {
    let mut on = mask.to_vec();
    let mut flagged = vec![false; on.len()];
    let mut cand: Vec<usize> = Vec::new();
    {
        let img = Img { nx, ny, on: &on };
        for i in 0..on.len() {
            if on[i] && img.ring(i).iter().any(|b| !b) {
                cand.push(i);
                flagged[i] = true;
            }
        }
    }
    let mut step = 0usize;
    let mut idle = 0;
    while idle < 2 && !cand.is_empty() {
        let first = step.is_multiple_of(2);
        step += 1;
        let del: Vec<usize> = {
            let img = Img { nx, ny, on: &on };
            cand.iter()
                .copied()
                .filter(|&i| {
                    if !on[i] {
                        return false;
                    }
                    let p = img.ring(i);
                    let b = p.iter().filter(|&&v| v).count();
                    if !(2..=6).contains(&b) || transitions(&p) != 1 {
                        return false;
                    }
                    let (p2, p4, p6, p8) = (p[0], p[2], p[4], p[6]);
                    if first {
                        !(p2 && p4 && p6) && !(p4 && p6 && p8)
                    } else {
                        !(p2 && p4 && p8) && !(p2 && p6 && p8)
                    }
                })
                .collect()
        };
        if del.is_empty() {
            idle += 1;
            continue;
        }
        idle = 0;
        for &i in &del {
            on[i] = false;
        }
        // Next candidates: surviving candidates and the solid neighbours of deleted pixels.
        let mut next = Vec::with_capacity(cand.len());
        for &i in &cand {
            flagged[i] = false;
        }
        let mut push = |i: usize, next: &mut Vec<usize>| {
            if on[i] && !flagged[i] {
                flagged[i] = true;
                next.push(i);
            }
        };
        for &i in &cand {
            push(i, &mut next);
        }
        for &i in &del {
            let (x, y) = ((i % nx) as isize, (i / nx) as isize);
            for (dx, dy) in RING {
                let (xx, yy) = (x + dx, y + dy);
                if xx >= 0 && yy >= 0 && (xx as usize) < nx && (yy as usize) < ny {
                    push(yy as usize * nx + xx as usize, &mut next);
                }
            }
        }
        cand = next;
    }
    on
}

/// Removes spurs from skeleton `skel` in place. `radius[i]` is the inscribed radius at pixel `i`
/// (pixels). Returns the number of pixels removed.
pub fn prune_spurs(nx: usize, ny: usize, skel: &mut [bool], radius: &[f64]) -> usize {
    let mut removed = 0;
    for _round in 0..4 {
        let ends: Vec<usize> = {
            let img = Img { nx, ny, on: skel };
            (0..skel.len())
                .filter(|&i| {
                    skel[i] && {
                        let p = img.ring(i);
                        p.iter().any(|&b| b) && transitions(&p) == 1
                    }
                })
                .collect()
        };
        let mut cut = Vec::new();
        for &e in &ends {
            if let Some(path) = spur(nx, ny, skel, radius, e) {
                cut.extend(path);
            }
        }
        if cut.is_empty() {
            break;
        }
        for i in cut {
            if skel[i] {
                skel[i] = false;
                removed += 1;
            }
        }
    }
    removed
}

/// Walks the terminal branch from endpoint `e`; returns its pixels if it is a spur.
fn spur(nx: usize, ny: usize, skel: &[bool], radius: &[f64], e: usize) -> Option<Vec<usize>> {
    let img = Img { nx, ny, on: skel };
    let mut path = vec![e];
    let mut len = 0.0;
    let mut cur = e;
    let junction = loop {
        let (x, y) = ((cur % nx) as isize, (cur / nx) as isize);
        let mut next: Option<(usize, f64, bool)> = None;
        for (k, (dx, dy)) in RING.iter().enumerate() {
            let (xx, yy) = (x + dx, y + dy);
            if !img.get(xx, yy) {
                continue;
            }
            let j = yy as usize * nx + xx as usize;
            if path.iter().rev().take(3).any(|&q| q == j) {
                continue;
            }
            let is_junction = transitions(&img.ring(j)) >= 3;
            let step = if k % 2 == 0 {
                1.0
            } else {
                std::f64::consts::SQRT_2
            };
            // Prefer a junction, then edge neighbours (walk staircases pixel by pixel).
            let better = match next {
                None => true,
                Some((_, s, jn)) => (is_junction && !jn) || (is_junction == jn && step < s),
            };
            if better {
                next = Some((j, step, is_junction));
            }
        }
        match next {
            // An isolated curve (no junction): a whole part's skeleton, never a spur.
            None => return None,
            Some((j, step, is_junction)) => {
                len += step;
                if is_junction {
                    break j;
                }
                path.push(j);
                cur = j;
                if path.len() > 100_000 {
                    return None;
                }
            }
        }
    };
    let rj = radius[junction];
    let rt = radius[e];
    let taper = (rj - rt) / len.max(1.0);
    (len <= 3.0 || taper >= 0.25).then_some(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interpret::distance::edt_squared;

    fn rect(nx: usize, ny: usize, x0: usize, x1: usize, y0: usize, y1: usize) -> Vec<bool> {
        (0..nx * ny)
            .map(|i| (x0..x1).contains(&(i % nx)) && (y0..y1).contains(&(i / nx)))
            .collect()
    }

    #[test]
    fn a_bar_thins_to_its_centre_line_and_loses_its_corner_spurs() {
        let (nx, ny) = (60, 21);
        let m = rect(nx, ny, 5, 55, 5, 16);
        let mut s = thin(nx, ny, &m);
        let void: Vec<bool> = m.iter().map(|b| !b).collect();
        let r: Vec<f64> = edt_squared([nx, ny, 1], &void, true)
            .iter()
            .map(|d| d.sqrt() - 0.5)
            .collect();
        prune_spurs(nx, ny, &mut s, &r);
        let pix: Vec<usize> = (0..s.len()).filter(|&i| s[i]).collect();
        // A horizontal line through the middle row (y = 10), with full radius everywhere.
        assert!(pix.len() > 30, "{}", pix.len());
        assert!(
            pix.iter().all(|&i| i / nx == 10),
            "{:?}",
            pix.iter().map(|i| (i % nx, i / nx)).collect::<Vec<_>>()
        );
        assert!(pix.iter().all(|&i| (r[i] - 5.5).abs() < 1e-9));
    }
}
