//! The broad phase: which facet pairs have overlapping bounding boxes, found on a hierarchical
//! uniform grid in time linear in the facets (and the pairs found), in parallel.
//!
//! Level 0's cell is as wide as the facets' boxes (the largest, or four times the median when a
//! few facets are much larger); level `l` has cells `4^l` times wider, and each facet lives on
//! the first level whose cell is at least as wide as its box, so it touches at most 2 cells per
//! axis there (8 in all). Two facets on one level share at least the cell that holds the
//! lowest corner of their boxes' intersection, and the pair is tested in that cell only (so once).
//! A facet on a finer level is tested against a coarser level's facets from the coarser level's
//! cells it touches (at most 8, looked up only when that level has facets at all); the pair is
//! again tested in the cell of its boxes' lowest common corner. So the work per facet is bounded
//! whatever the spread of facet sizes: on a mesh of near-uniform facets (every mesh latvox makes)
//! all facets are on level 0; a CAD mesh with long thin facets beside small ones puts the long
//! ones on coarser levels instead of into thousands of fine cells.
//!
//! Cells are grouped into bricks of 16³ searched in parallel, each with its own counting sort of
//! its facets into cells, so the memory beyond the mesh is a few bytes per facet.

use super::exact::{collinear, facets_intersect, settled_by_sharing, Facet, P};
use crate::progress::Progress;
use rayon::prelude::*;
use std::collections::{HashMap, HashSet};
use std::sync::Mutex;

/// Cells per brick side, as a shift.
const BRICK_SHIFT: u32 = 4;
const BRICK: usize = 1 << BRICK_SHIFT;
/// Cells per axis must fit in this many bits.
const AXIS_BITS: u32 = 20;
/// Each level's cell is this many times wider than the one below.
const LEVEL_RATIO: f64 = 4.0;
/// Level 0's cell is at most this many median facet widths (facets wider go up a level).
const MEDIAN_RATIO: f64 = 4.0;

/// Intersecting pairs among `tris` (vertex indices into `positions`, xyz triples, finite), as
/// indices into `tris`, smaller first, sorted; a facet whose corners are collinear is paired with
/// itself (as CGAL reports a degenerate facet) and takes no other part. The star vertices (see
/// [`super::fans`]) come from `stars`, computed while the facets are bucketed.
pub fn intersecting_pairs(
    positions: &[f32],
    tris: &[[u32; 3]],
    stars: Stars<'_>,
    progress: &Progress,
) -> Vec<(u32, u32)> {
    let point = |v: u32| -> P {
        let i = 3 * v as usize;
        [
            positions[i] as f64,
            positions[i + 1] as f64,
            positions[i + 2] as f64,
        ]
    };
    let bbox = |t: &[u32; 3]| -> [[f32; 3]; 2] {
        let (i, j, k) = (3 * t[0] as usize, 3 * t[1] as usize, 3 * t[2] as usize);
        let (a, b, c) = (
            &positions[i..i + 3],
            &positions[j..j + 3],
            &positions[k..k + 3],
        );
        [
            [
                a[0].min(b[0]).min(c[0]),
                a[1].min(b[1]).min(c[1]),
                a[2].min(b[2]).min(c[2]),
            ],
            [
                a[0].max(b[0]).max(c[0]),
                a[1].max(b[1]).max(c[1]),
                a[2].max(b[2]).max(c[2]),
            ],
        ]
    };
    let width = |b: &[[f32; 3]; 2]| {
        (b[1][0] - b[0][0])
            .max(b[1][1] - b[0][1])
            .max(b[1][2] - b[0][2])
    };
    if tris.len() < 2 {
        return tris
            .iter()
            .enumerate()
            .filter(|(_, t)| {
                let [a, b, c] = t.map(point);
                collinear(&a, &b, &c)
            })
            .map(|(i, _)| (i as u32, i as u32))
            .collect();
    }

    // The bounds and the widths.
    let (lo, hi, max_width) = tris
        .par_iter()
        .map(|t| {
            let b = bbox(t);
            (b[0], b[1], width(&b))
        })
        .reduce(
            || ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3], 0.0f32),
            |x, y| {
                (
                    [0, 1, 2].map(|i| x.0[i].min(y.0[i])),
                    [0, 1, 2].map(|i| x.1[i].max(y.1[i])),
                    x.2.max(y.2),
                )
            },
        );
    // Readers refuse non-finite coordinates; a library caller's would make the grid meaningless.
    assert!(
        lo.iter().chain(&hi).all(|x| x.is_finite()),
        "self-intersection search: non-finite vertex coordinates"
    );
    let step = (tris.len() / 65_536).max(1);
    let mut sample: Vec<f32> = (0..tris.len())
        .step_by(step)
        .map(|i| width(&bbox(&tris[i])))
        .collect();
    let mid = sample.len() / 2;
    let median = if sample.is_empty() {
        max_width
    } else {
        *sample.select_nth_unstable_by(mid, f32::total_cmp).1
    };
    let span = (0..3).map(|i| (hi[i] - lo[i]) as f64).fold(0.0, f64::max);
    let mut h0 = (max_width as f64).min(MEDIAN_RATIO * median as f64);
    // Cells per axis fit the key; a mesh of points only still gets a cell.
    h0 = h0.max(span / (1u64 << AXIS_BITS) as f64 * 2.0);
    if h0.is_nan() || h0 <= 0.0 {
        h0 = 1.0;
    }
    let origin = lo.map(|x| x as f64);
    let cell_width = |level: u32| h0 * LEVEL_RATIO.powi(level as i32);
    let level_of = |w: f32| {
        let mut l = 0;
        while (w as f64) > cell_width(l) {
            l += 1;
        }
        l
    };
    let cells = |b: &[[f32; 3]; 2], level: u32| -> [[i64; 3]; 2] {
        let h = cell_width(level);
        // x ≥ origin: truncation is the floor.
        let c = |x: f32, i: usize| ((x as f64 - origin[i]) / h) as i64;
        [
            [c(b[0][0], 0), c(b[0][1], 1), c(b[0][2], 2)],
            [c(b[1][0], 0), c(b[1][1], 1), c(b[1][2], 2)],
        ]
    };
    let brick_key = |level: u32, b: [i64; 3]| -> u64 {
        ((level as u64) << 60)
            | ((b[0] as u64) << (2 * AXIS_BITS))
            | ((b[1] as u64) << AXIS_BITS)
            | b[2] as u64
    };
    let cell_key = |c: [i64; 3]| -> u64 {
        ((c[0] as u64) << (2 * AXIS_BITS)) | ((c[1] as u64) << AXIS_BITS) | c[2] as u64
    };

    // Facets into the bricks of their level (natives), and as queries into coarser levels'
    // bricks, while the star vertices are found. Degenerate facets are bucketed too, and found
    // where their boxes are (in parallel); they take part in no pair.
    let bucketing = || {
        let level_of_facet = |i: usize| level_of(width(&bbox(&tris[i])));
        let mut bricks: HashMap<u64, Bucket> = HashMap::new();
        let natives = bucket(tris.len(), |i, push| {
            let b = bbox(&tris[i]);
            let l = level_of(width(&b));
            for_each_brick(cells(&b, l), |k| push(brick_key(l, k), i as u32));
        });
        let top = natives.keys().map(|k| (k >> 60) as u32).max().unwrap_or(0);
        for (k, v) in natives {
            bricks.entry(k).or_default().natives = v;
        }
        // Facets of finer levels as queries on each coarser level that has facets.
        for coarse in 1..=top {
            let on_level: Vec<usize> = (0..tris.len())
                .into_par_iter()
                .filter(|&i| level_of_facet(i) == coarse)
                .collect();
            let occupied: HashSet<u64> = on_level
                .iter()
                .flat_map(|&i| {
                    let mut keys = Vec::with_capacity(8);
                    for_each_cell(cells(&bbox(&tris[i]), coarse), |x| keys.push(cell_key(x)));
                    keys
                })
                .collect();
            if occupied.is_empty() {
                continue;
            }
            let queries = bucket(tris.len(), |i, push| {
                let b = bbox(&tris[i]);
                if level_of(width(&b)) >= coarse {
                    return;
                }
                let c = cells(&b, coarse);
                let mut hit = false;
                for_each_cell(c, |x| hit |= occupied.contains(&cell_key(x)));
                if hit {
                    for_each_brick(c, |k| push(brick_key(coarse, k), i as u32));
                }
            });
            for (k, v) in queries {
                bricks.entry(k).or_default().queries = v;
            }
        }
        bricks.into_iter().collect::<Vec<(u64, Bucket)>>()
    };
    let (bricks, star) = rayon::join(bucketing, || stars.get(positions, tris));
    let star = &star[..];

    // Each brick searched on its own.
    let counter = progress.counter(bricks.len() as u64, "blocks of facets searched");
    let found = Mutex::new(Vec::new());
    bricks.par_iter().for_each(|(key, bucket)| {
        let level = (key >> 60) as u32;
        let mask = (1u64 << AXIS_BITS) - 1;
        let base = [
            ((key >> (2 * AXIS_BITS)) & mask) as i64,
            ((key >> AXIS_BITS) & mask) as i64,
            (key & mask) as i64,
        ]
        .map(|x| x << BRICK_SHIFT);
        let mut local = Vec::new();
        let stars_of = |t: [u32; 3]| (0..3).fold(0u8, |m, k| m | (star[t[k] as usize] as u8) << k);
        // Natives sorted by their boxes' lower x, so that each cell's list is too (the counting
        // sort is stable) and a facet's partners in a cell end at the first box starting past
        // its own. Degenerate ones are reported in the brick of their box's lower corner.
        let mut natives = Vec::with_capacity(bucket.natives.len());
        for &id in &bucket.natives {
            let t = tris[id as usize];
            let p = t.map(point);
            let b = bbox(&t);
            let c = cells(&b, level);
            if collinear(&p[0], &p[1], &p[2]) {
                if (0..3).all(|i| c[0][i] >> BRICK_SHIFT == base[i] >> BRICK_SHIFT) {
                    local.push((id, id));
                }
                continue;
            }
            natives.push(Member::new(id, t, stars_of(t), b, c, base));
        }
        natives.sort_unstable_by(|a, b| a.lo[0].total_cmp(&b.lo[0]));
        let queries: Vec<Member> = bucket
            .queries
            .iter()
            .filter_map(|&id| {
                let t = tris[id as usize];
                let p = t.map(point);
                let b = bbox(&t);
                (!collinear(&p[0], &p[1], &p[2]))
                    .then(|| Member::new(id, t, stars_of(t), b, cells(&b, level), base))
            })
            .collect();
        let nat_cells = sort_into_cells(&natives);
        let qry_cells = sort_into_cells(&queries);
        let mut test = |a: &Member, b: &Member| {
            // Most pairs share a vertex of a proven fan: their corners are not even read.
            if settled_by_sharing(&a.verts, a.stars, &b.verts) {
                return;
            }
            let facet = |t: [u32; 3]| Facet::new(t, t.map(point));
            if facets_intersect(&facet(a.verts), &facet(b.verts)) {
                let (f, g) = (a.id, b.id);
                local.push((f.min(g), f.max(g)));
            }
        };
        // A cell's members, copied side by side with their corner masks: bit `a` when the
        // member's lowest cell is this one on axis `a`. A pair is tested only in the cell of the
        // lowest corner of its boxes' intersection: where the two masks cover all three axes.
        let (mut here, mut asked) = (Vec::new(), Vec::new());
        let gather = |out: &mut Vec<Member>, all: &[Member], ids: &[u32], cell: [i8; 3]| {
            out.clear();
            out.extend(ids.iter().map(|&i| {
                let mut m = all[i as usize];
                m.mask = (0..3).fold(0, |k, a| k | ((m.lo_cell[a] == cell[a]) as u8) << a);
                m
            }));
        };
        for c in 0..BRICK * BRICK * BRICK {
            let n = &nat_cells.1[nat_cells.0[c] as usize..nat_cells.0[c + 1] as usize];
            if n.is_empty() {
                continue;
            }
            let cell = [
                (c / (BRICK * BRICK)) as i8,
                ((c / BRICK) % BRICK) as i8,
                (c % BRICK) as i8,
            ];
            gather(&mut here, &natives, n, cell);
            for (k, a) in here.iter().enumerate() {
                for b in &here[k + 1..] {
                    // Sorted by lower x: the boxes overlap along x until b starts past a.
                    if b.lo[0] > a.hi[0] {
                        break;
                    }
                    if a.mask | b.mask == 7 && a.overlaps_yz(b) {
                        test(a, b);
                    }
                }
            }
            let q = &qry_cells.1[qry_cells.0[c] as usize..qry_cells.0[c + 1] as usize];
            if q.is_empty() {
                continue;
            }
            gather(&mut asked, &queries, q, cell);
            for a in &asked {
                for b in &here {
                    if a.mask | b.mask == 7
                        && a.lo[0] <= b.hi[0]
                        && b.lo[0] <= a.hi[0]
                        && a.overlaps_yz(b)
                    {
                        test(a, b);
                    }
                }
            }
        }
        if !local.is_empty() {
            found
                .lock()
                .expect("no panic while holding the lock")
                .extend(local);
        }
        counter.inc();
    });
    let mut pairs = found.into_inner().expect("no panic while holding the lock");
    pairs.par_sort_unstable();
    pairs
}

/// A facet of a brick, as the broad phase scans it: its box, its cells (relative to the brick's,
/// clamped), vertex indices, star bits (bit k: corner k's vertex is proven, see
/// [`super::fans`]) and id. The corners are read only for the pairs that need the exact tests.
#[derive(Clone, Copy)]
struct Member {
    lo: [f32; 3],
    hi: [f32; 3],
    verts: [u32; 3],
    id: u32,
    lo_cell: [i8; 3],
    hi_cell: [i8; 3],
    stars: u8,
    /// Per cell scanned: the axes on which the lowest cell is that cell.
    mask: u8,
}

impl Member {
    fn new(
        id: u32,
        verts: [u32; 3],
        stars: u8,
        b: [[f32; 3]; 2],
        c: [[i64; 3]; 2],
        base: [i64; 3],
    ) -> Member {
        // Within the brick a facet's cells run from -2 to 17; anything further is clamped
        // (it equals no cell of the brick either way).
        let rel = |x: [i64; 3]| [0, 1, 2].map(|a| (x[a] - base[a]).clamp(-64, 64) as i8);
        Member {
            lo: b[0],
            hi: b[1],
            verts,
            id,
            lo_cell: rel(c[0]),
            hi_cell: rel(c[1]),
            stars,
            mask: 0,
        }
    }

    #[inline]
    fn overlaps_yz(&self, o: &Member) -> bool {
        self.lo[1] <= o.hi[1]
            && o.lo[1] <= self.hi[1]
            && self.lo[2] <= o.hi[2]
            && o.lo[2] <= self.hi[2]
    }
}

/// Where the search gets its star vertices (see [`super::fans`]) from.
pub enum Stars<'a> {
    /// Computed from the facets searched.
    Own,
    /// The caller's function's, per vertex of the positions (of these facets or of a mesh
    /// holding them).
    Beside(Box<dyn FnOnce() -> Vec<bool> + Send + 'a>),
}

impl Stars<'_> {
    fn get(self, positions: &[f32], tris: &[[u32; 3]]) -> Vec<bool> {
        match self {
            Stars::Own => super::fans::star_vertices(positions, tris),
            Stars::Beside(f) => f(),
        }
    }
}

#[derive(Default)]
struct Bucket {
    natives: Vec<u32>,
    queries: Vec<u32>,
}

/// Facet ids bucketed by key in parallel: `place(i, push)` pushes facet `i` under its keys.
/// Neighbouring facets mostly share a key, so each thread gathers runs of one key before it
/// touches its map.
fn bucket<F>(n: usize, place: F) -> HashMap<u64, Vec<u32>>
where
    F: Fn(usize, &mut dyn FnMut(u64, u32)) + Sync,
{
    const CHUNK: usize = 1 << 14;
    (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .fold(HashMap::new, |mut m: HashMap<u64, Vec<u32>>, chunk| {
            let mut run: (u64, Vec<u32>) = (u64::MAX, Vec::new());
            for i in chunk * CHUNK..((chunk + 1) * CHUNK).min(n) {
                place(i, &mut |k, id| {
                    if k != run.0 {
                        if !run.1.is_empty() {
                            m.entry(run.0).or_default().append(&mut run.1);
                        }
                        run.0 = k;
                    }
                    run.1.push(id);
                });
            }
            if !run.1.is_empty() {
                m.entry(run.0).or_default().append(&mut run.1);
            }
            m
        })
        .reduce(HashMap::new, |mut a, b| {
            if a.len() < b.len() {
                return merge(b, a);
            }
            merge_into(&mut a, b);
            a
        })
}

fn merge(mut a: HashMap<u64, Vec<u32>>, b: HashMap<u64, Vec<u32>>) -> HashMap<u64, Vec<u32>> {
    merge_into(&mut a, b);
    a
}

fn merge_into(a: &mut HashMap<u64, Vec<u32>>, b: HashMap<u64, Vec<u32>>) {
    for (k, v) in b {
        a.entry(k).or_default().extend(v);
    }
}

fn for_each_cell(c: [[i64; 3]; 2], mut f: impl FnMut([i64; 3])) {
    for x in c[0][0]..=c[1][0] {
        for y in c[0][1]..=c[1][1] {
            for z in c[0][2]..=c[1][2] {
                f([x, y, z]);
            }
        }
    }
}

fn for_each_brick(c: [[i64; 3]; 2], f: impl FnMut([i64; 3])) {
    let s = BRICK_SHIFT;
    for_each_cell([c[0].map(|x| x >> s), c[1].map(|x| x >> s)], f);
}

/// A counting sort of a brick's members into its cells: cell `c`'s members are
/// `list[starts[c]..starts[c + 1]]` (positions in `members`, in their order).
fn sort_into_cells(members: &[Member]) -> (Vec<u32>, Vec<u32>) {
    let n = BRICK * BRICK * BRICK;
    let last = BRICK as i8 - 1;
    let local = |m: &Member, f: &mut dyn FnMut(usize)| {
        let lo = m.lo_cell.map(|x| x.max(0) as usize);
        let hi = m.hi_cell.map(|x| x.min(last) as usize);
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    f((x * BRICK + y) * BRICK + z);
                }
            }
        }
    };
    let mut starts = vec![0u32; n + 1];
    for m in members {
        local(m, &mut |c| starts[c + 1] += 1);
    }
    for c in 0..n {
        starts[c + 1] += starts[c];
    }
    let mut fill = starts.clone();
    let mut list = vec![0u32; starts[n] as usize];
    for (k, m) in members.iter().enumerate() {
        local(m, &mut |c| {
            list[fill[c] as usize] = k as u32;
            fill[c] += 1;
        });
    }
    (starts, list)
}
