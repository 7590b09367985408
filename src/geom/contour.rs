//! Plane contours: closed loops of a section — from a mesh, or by marching squares over samples
//! of a field ([`iso_loops`]) — measured (area, perimeter) and nested into polygons with holes.
//! Loops follow one convention everywhere: the solid on the left, so outer boundaries run
//! counter-clockwise and holes clockwise.

/// A closed polyline in mm (first point not repeated at the end).
pub type Loop = Vec<[f64; 2]>;

/// One layer's cut: its closed loops, and the chains that could not close (only on an invalid
/// mesh: a hole or a non-manifold edge crosses the plane).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Section {
    /// Closed loops, solid on the left.
    pub loops: Vec<Loop>,
    /// Open chains (start and end points included).
    pub open: Vec<Vec<[f64; 2]>>,
}

/// A polygon: an outer loop and the holes directly inside it, as indices into a section's loops.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Polygon {
    /// The counter-clockwise boundary.
    pub outer: usize,
    /// The clockwise loops directly inside it.
    pub holes: Vec<usize>,
}

/// A layer's measures.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct Measures {
    /// Enclosed area (holes subtracted), mm².
    pub area: f64,
    /// Total length of the loops, mm.
    pub perimeter: f64,
    /// Closed loops.
    pub loops: usize,
    /// Loops that bound holes (clockwise).
    pub holes: usize,
    /// Chains that could not close.
    pub open: usize,
}

impl Section {
    /// Area, perimeter and loop counts.
    pub fn measures(&self) -> Measures {
        let areas: Vec<f64> = self.loops.iter().map(|l| signed_area(l)).collect();
        Measures {
            area: areas.iter().sum(),
            perimeter: self.loops.iter().map(|l| perimeter(l)).sum(),
            loops: self.loops.len(),
            holes: areas.iter().filter(|&&a| a < 0.0).count(),
            open: self.open.len(),
        }
    }

    /// The loops nested into polygons (see [`polygons`]).
    pub fn polygons(&self) -> Vec<Polygon> {
        polygons(&self.loops)
    }
}

/// Signed area (positive counter-clockwise), mm².
pub fn signed_area(l: &[[f64; 2]]) -> f64 {
    let n = l.len();
    if n < 3 {
        return 0.0;
    }
    // Relative to the first point: the same sum, less cancellation far from the origin.
    let o = l[0];
    let mut s = 0.0;
    for i in 1..n - 1 {
        let (a, b) = (l[i], l[i + 1]);
        s += (a[0] - o[0]) * (b[1] - o[1]) - (b[0] - o[0]) * (a[1] - o[1]);
    }
    0.5 * s
}

/// Length of a closed loop, mm.
pub fn perimeter(l: &[[f64; 2]]) -> f64 {
    let n = l.len();
    (0..n)
        .map(|i| {
            let (a, b) = (l[i], l[(i + 1) % n]);
            (b[0] - a[0]).hypot(b[1] - a[1])
        })
        .sum()
}

/// Even–odd point-in-polygon test.
pub fn contains(l: &[[f64; 2]], p: [f64; 2]) -> bool {
    let mut inside = false;
    let n = l.len();
    for i in 0..n {
        let (a, b) = (l[i], l[(i + 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// Groups loops into polygons: each counter-clockwise loop with the clockwise loops (holes)
/// directly inside it — a hole's parent is the smallest outer loop around it. Outer loops are
/// found from a hole's first point through a uniform grid of the outers' bounding boxes, so a
/// layer of a large lattice (thousands of loops) nests in near-linear time. A hole inside no
/// outer loop (only from an invalid mesh) is left out of every polygon.
pub fn polygons(loops: &[Loop]) -> Vec<Polygon> {
    let areas: Vec<f64> = loops.iter().map(|l| signed_area(l)).collect();
    let outers: Vec<usize> = (0..loops.len()).filter(|&i| areas[i] > 0.0).collect();
    let mut polys: Vec<Polygon> = outers
        .iter()
        .map(|&i| Polygon {
            outer: i,
            holes: Vec::new(),
        })
        .collect();
    let holes: Vec<usize> = (0..loops.len()).filter(|&i| areas[i] <= 0.0).collect();
    if holes.is_empty() || outers.is_empty() {
        return polys;
    }
    let boxes: Vec<[f64; 4]> = outers.iter().map(|&i| bbox(&loops[i])).collect();
    let all = boxes.iter().fold(EMPTY_BOX, |a, &b| merge(a, b));
    let g = ((outers.len() as f64).sqrt().ceil() as usize).clamp(1, 1024);
    let (w, h) = (
        ((all[2] - all[0]) / g as f64).max(1e-300),
        ((all[3] - all[1]) / g as f64).max(1e-300),
    );
    let cell = |x: f64, y: f64| -> (usize, usize) {
        (
            (((x - all[0]) / w) as usize).min(g - 1),
            (((y - all[1]) / h) as usize).min(g - 1),
        )
    };
    let mut grid: Vec<Vec<u32>> = vec![Vec::new(); g * g];
    for (k, b) in boxes.iter().enumerate() {
        let (i0, j0) = cell(b[0], b[1]);
        let (i1, j1) = cell(b[2], b[3]);
        for j in j0..=j1 {
            for i in i0..=i1 {
                grid[j * g + i].push(k as u32);
            }
        }
    }
    for hole in holes {
        let p = loops[hole][0];
        if p[0] < all[0] || p[0] > all[2] || p[1] < all[1] || p[1] > all[3] {
            continue;
        }
        let (i, j) = cell(p[0], p[1]);
        let parent = grid[j * g + i]
            .iter()
            .map(|&k| k as usize)
            .filter(|&k| {
                let b = boxes[k];
                p[0] >= b[0] && p[0] <= b[2] && p[1] >= b[1] && p[1] <= b[3]
            })
            .filter(|&k| contains(&loops[outers[k]], p))
            .min_by(|&a, &b| areas[outers[a]].total_cmp(&areas[outers[b]]));
        if let Some(k) = parent {
            polys[k].holes.push(hole);
        }
    }
    polys
}

/// Loops of `{f ≥ level}` by marching squares over an `n[0] × n[1]` grid of samples `f(i, j)`,
/// in grid units (sample `(i, j)` at `(i, j)`), solid on the left. Beyond the grid the value is
/// `outside` (below `level`), so every loop closes. Saddle cells are resolved by the cell-centre
/// average; a crossing is never put exactly on a sample, so loops never touch.
pub fn iso_loops(
    n: [usize; 2],
    f: impl Fn(usize, usize) -> f64,
    level: f64,
    outside: f64,
) -> Vec<Loop> {
    let (nx, ny) = (n[0], n[1]);
    let (w, hgt) = (nx + 2, ny + 2);
    let val = |i: usize, j: usize| -> f64 {
        if i == 0 || j == 0 || i > nx || j > ny {
            outside
        } else {
            f(i - 1, j - 1)
        }
    };
    let inside = |i: usize, j: usize| val(i, j) >= level;
    // Edge ids: horizontal (i,j)-(i+1,j) and vertical (i,j)-(i,j+1).
    let hid = |i: usize, j: usize| j * (w - 1) + i;
    let voff = (w - 1) * hgt;
    let vid = |i: usize, j: usize| voff + j * w + i;
    let total = voff + w * (hgt - 1);
    let mut next = vec![u32::MAX; total];
    for j in 0..hgt - 1 {
        for i in 0..w - 1 {
            let c = [
                inside(i, j),
                inside(i + 1, j),
                inside(i + 1, j + 1),
                inside(i, j + 1),
            ];
            if c.iter().all(|&b| b) || c.iter().all(|&b| !b) {
                continue;
            }
            // Edges walked counter-clockwise: bottom, right, top, left.
            let e = [hid(i, j), vid(i + 1, j), hid(i, j + 1), vid(i, j)];
            let exits: Vec<usize> = (0..4).filter(|&k| c[k] && !c[(k + 1) % 4]).collect();
            let entries: Vec<usize> = (0..4).filter(|&k| !c[k] && c[(k + 1) % 4]).collect();
            if exits.len() == 1 {
                next[e[exits[0]]] = e[entries[0]] as u32;
            } else {
                // Saddle: two solid corners on a diagonal.
                let centre = 0.25 * (val(i, j) + val(i + 1, j) + val(i + 1, j + 1) + val(i, j + 1));
                for &x in &exits {
                    // Joined through the centre: pair each exit with the following entry;
                    // separate: with the preceding one.
                    let en = if centre >= level {
                        (x + 1) % 4
                    } else {
                        (x + 3) % 4
                    };
                    next[e[x]] = e[en] as u32;
                }
            }
        }
    }
    let point = |id: usize| -> [f64; 2] {
        let ((i0, j0), (i1, j1)) = if id < voff {
            let (j, i) = (id / (w - 1), id % (w - 1));
            ((i, j), (i + 1, j))
        } else {
            let k = id - voff;
            let (j, i) = (k / w, k % w);
            ((i, j), (i, j + 1))
        };
        let (a, b) = (val(i0, j0), val(i1, j1));
        let t = ((level - a) / (b - a)).clamp(1e-3, 1.0 - 1e-3);
        let p = |i: usize| i as f64 - 1.0;
        [p(i0) + t * (p(i1) - p(i0)), p(j0) + t * (p(j1) - p(j0))]
    };
    let mut out = Vec::new();
    for s in 0..total {
        if next[s] == u32::MAX {
            continue;
        }
        let mut l = Vec::new();
        let mut cur = s;
        while next[cur] != u32::MAX {
            l.push(point(cur));
            let n = next[cur] as usize;
            next[cur] = u32::MAX;
            cur = n;
        }
        if l.len() >= 3 {
            out.push(l);
        }
    }
    out
}

/// A 2-D box `[xmin, ymin, xmax, ymax]` holding nothing.
pub const EMPTY_BOX: [f64; 4] = [
    f64::INFINITY,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::NEG_INFINITY,
];

/// Box `b` grown to hold point `p`.
pub fn grow(b: [f64; 4], p: [f64; 2]) -> [f64; 4] {
    [
        b[0].min(p[0]),
        b[1].min(p[1]),
        b[2].max(p[0]),
        b[3].max(p[1]),
    ]
}

/// The box holding boxes `a` and `b`.
pub fn merge(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0].min(b[0]),
        a[1].min(b[1]),
        a[2].max(b[2]),
        a[3].max(b[3]),
    ]
}

/// `[xmin, ymin, xmax, ymax]` of a loop.
pub fn bbox(l: &[[f64; 2]]) -> [f64; 4] {
    l.iter().fold(EMPTY_BOX, |a, &p| grow(a, p))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(c: [f64; 2], r: f64, ccw: bool) -> Loop {
        let mut l = vec![
            [c[0] - r, c[1] - r],
            [c[0] + r, c[1] - r],
            [c[0] + r, c[1] + r],
            [c[0] - r, c[1] + r],
        ];
        if !ccw {
            l.reverse();
        }
        l
    }

    #[test]
    fn nested_squares_nest_to_their_smallest_outer() {
        // An outer with a hole, an island in the hole with its own hole, and a far square.
        let loops = vec![
            square([0.0, 0.0], 10.0, true),
            square([0.0, 0.0], 8.0, false),
            square([0.0, 0.0], 5.0, true),
            square([0.0, 0.0], 2.0, false),
            square([30.0, 0.0], 1.0, true),
        ];
        let p = polygons(&loops);
        assert_eq!(p.len(), 3);
        assert_eq!(p[0].holes, vec![1]);
        assert_eq!(p[1].holes, vec![3]);
        assert!(p[2].holes.is_empty());
        let s = Section {
            loops,
            open: vec![],
        };
        let m = s.measures();
        assert_eq!((m.loops, m.holes), (5, 2));
        assert!((m.area - (400.0 - 256.0 + 100.0 - 16.0 + 4.0)).abs() < 1e-9);
        assert!((m.perimeter - 8.0 * (10.0 + 8.0 + 5.0 + 2.0 + 1.0)).abs() < 1e-9);
    }
}
