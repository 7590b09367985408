//! A periodic strut lattice as a [`Field`], evaluated in one cell.
//!
//! The query mapping of the augmented sphere-tracing method for periodic lattices (Guo & Li,
//! "Augmented sphere tracing … mega-scale periodic shell-lattice", Computer-Aided Design 184,
//! 2025): a point `p` maps into the cell as `q = (p − origin) mod s − s/2`, so the whole
//! lattice is evaluated by looking at one cell. *Strut augmentation* makes that exact: every
//! strut whose rounded end reaches past a face, edge or corner of the cell is copied into the
//! cell from the 2, 4 or 8 cells around it — here every translate of every strut that comes
//! within reach of the cell is kept. A small grid of bins inside the cell then lists, for each
//! bin, the struts that come within reach of it, so a sample looks at a few struts, not all.
//!
//! The lattice description (the augmented struts and the bins) depends on the cell alone, never
//! on how many cells the part has.
//!
//! Values are the exact signed distance to the union of the struts (rounded cones; capsules
//! where both ends have the same radius) up to the *reach*, and the reach beyond it; with
//! `blend > 0` struts meet in a smooth minimum of that radius (Quilez's polynomial smooth
//! minimum), still 1-Lipschitz, so the clearance is the value's magnitude.

use super::cell::UnitCell;
use crate::field::{numeric_gradient, periodic, smooth_min, Field, Vec3};

/// Bins per axis of the cell's index.
pub const BINS: usize = 4;

/// One strut of the augmented cell, in the cell's centred coordinates (mm).
#[derive(Debug, Clone, Copy)]
struct Strut {
    a: Vec3,
    /// `b − a`.
    ab: Vec3,
    /// `|b − a|²`.
    len2: f64,
    /// Radius factors at `a` and `b` (times the lattice's radius).
    fa: f64,
    fb: f64,
}

impl Strut {
    fn new(a: Vec3, b: Vec3, fa: f64, fb: f64) -> Strut {
        let ab = sub(b, a);
        Strut {
            a,
            ab,
            len2: dot(ab, ab),
            fa,
            fb,
        }
    }

    /// Signed distance from `p` to the strut at lattice radius `r`: a capsule, or a rounded
    /// cone when the ends' radii differ (Quilez's exact round-cone distance; the ends' spheres
    /// must not contain each other).
    fn distance(&self, p: Vec3, r: f64) -> f64 {
        let (ra, rb) = (r * self.fa, r * self.fb);
        let ap = sub(p, self.a);
        if ra == rb {
            let t = (dot(ap, self.ab) / self.len2).clamp(0.0, 1.0);
            let d = sub(ap, scale(self.ab, t));
            return dot(d, d).sqrt() - ra;
        }
        let (l2, rr) = (self.len2, ra - rb);
        let a2 = l2 - rr * rr;
        let il2 = 1.0 / l2;
        let y = dot(ap, self.ab);
        let z = y - l2;
        let w = sub(scale(ap, l2), scale(self.ab, y));
        let x2 = dot(w, w);
        let y2 = y * y * l2;
        let z2 = z * z * l2;
        let k = rr.signum() * rr * rr * x2;
        if z.signum() * a2 * z2 > k {
            return (x2 + z2).sqrt() * il2 - rb;
        }
        if y.signum() * a2 * y2 < k {
            return (x2 + y2).sqrt() * il2 - ra;
        }
        ((x2 * a2 * il2).sqrt() + y * rr) * il2 - ra
    }

    /// The gradient of [`Strut::distance`] at `p`: away from the axis for a capsule; by central
    /// differences of this strut's distance alone for a rounded cone (or on the axis).
    fn gradient(&self, p: Vec3, r: f64) -> Vec3 {
        if self.fa == self.fb {
            let ap = sub(p, self.a);
            let t = (dot(ap, self.ab) / self.len2).clamp(0.0, 1.0);
            let d = sub(ap, scale(self.ab, t));
            let n = dot(d, d).sqrt();
            if n > 0.0 {
                return scale(d, 1.0 / n);
            }
        }
        numeric_gradient(|q| self.distance(q, r), p)
    }

    /// The strut's bounding box at lattice radius `r`, grown by `m`.
    fn bounds(&self, r: f64, m: f64) -> [Vec3; 2] {
        let b = add(self.a, self.ab);
        let r = r * self.fa.max(self.fb) + m;
        [
            [0, 1, 2].map(|k| self.a[k].min(b[k]) - r),
            [0, 1, 2].map(|k| self.a[k].max(b[k]) + r),
        ]
    }
}

/// A periodic lattice of struts.
#[derive(Debug, Clone)]
pub struct StrutField {
    /// Cell size per axis, mm.
    cell: Vec3,
    /// A cell's lower corner, mm.
    origin: Vec3,
    /// Strut radius, mm (times each node's factor).
    radius: f64,
    blend: f64,
    /// Distances beyond this are reported as this.
    reach: f64,
    struts: Vec<Strut>,
    /// Per bin, `struts` indices; bin `(i, j, k)` at `(i·BINS + j)·BINS + k`.
    bins: Vec<Vec<u32>>,
    /// Samples per cell along each axis where a cell holds a whole number of samples of size
    /// `h` (0 where it does not), and `h`: block sampling then takes each sample's place in the
    /// cell from its index modulo the count, so that samples a cell apart are bit-identical.
    samples_per_cell: Option<([u32; 3], f64)>,
}

impl StrutField {
    /// The lattice of `cell` with cells of `size` mm (per axis) starting at `origin`, struts of
    /// radius `radius` mm (times each node's factor), joints blended over `blend` mm, its
    /// distance exact up to `reach` mm (at least the narrow band that will be sampled). The
    /// index is built for radii up to `radius` ([`StrutField::value_at`] may ask for less).
    pub fn new(
        cell: &UnitCell,
        size: Vec3,
        origin: Vec3,
        radius: f64,
        blend: f64,
        reach: f64,
    ) -> StrutField {
        let half = scale(size, 0.5);
        let mut struts = Vec::new();
        // Every translate of every strut that comes within the reach of the cell (in its
        // centred coordinates, [−s/2, s/2]³): a strut of the canonical cell has its midpoint
        // in the cell, so translates by up to two cells cover struts as long as √3 cells.
        let m = reach + blend;
        for ([a, b], [fa, fb]) in cell.segments(size) {
            for n in 0..125 {
                let shift = [n % 5, (n / 5) % 5, n / 25].map(|x| x as f64 - 2.0);
                let t = [0, 1, 2].map(|k| shift[k] * size[k] - half[k]);
                let s = Strut::new(add(a, t), add(b, t), fa, fb);
                let [lo, hi] = s.bounds(radius, m);
                if (0..3).all(|k| lo[k] <= half[k] && hi[k] >= -half[k]) {
                    struts.push(s);
                }
            }
        }
        let mut bins = vec![Vec::new(); BINS * BINS * BINS];
        for (i, bin) in bins.iter_mut().enumerate() {
            let idx = [i / (BINS * BINS), (i / BINS) % BINS, i % BINS];
            let lo = [0, 1, 2].map(|k| -half[k] + size[k] * idx[k] as f64 / BINS as f64);
            let hi = [0, 1, 2].map(|k| -half[k] + size[k] * (idx[k] + 1) as f64 / BINS as f64);
            for (j, s) in struts.iter().enumerate() {
                let [slo, shi] = s.bounds(radius, m);
                if (0..3).all(|k| slo[k] <= hi[k] && shi[k] >= lo[k]) {
                    bin.push(j as u32);
                }
            }
        }
        StrutField {
            cell: size,
            origin,
            radius,
            blend,
            reach,
            struts,
            bins,
            samples_per_cell: None,
        }
    }

    /// Turns on index-periodic block sampling along each axis where a cell spans a whole number
    /// of voxels `h`.
    pub fn with_periodic_samples(mut self, h: f64) -> Self {
        self.samples_per_cell = periodic::samples_per_cell(self.cell, h);
        self
    }

    /// The value at `p` with every strut's radius `r` (at most the radius the field was built
    /// for) instead of the field's.
    pub fn value_at(&self, p: Vec3, r: f64) -> f64 {
        let (q, bin) = self.locate(p);
        self.local_value(q, bin, r)
    }

    /// The value at `q`, in the cell's centred coordinates, in bin `bin`, at radius `r`.
    fn local_value(&self, q: Vec3, bin: usize, r: f64) -> f64 {
        let mut d = self.reach;
        for &i in &self.bins[bin] {
            let di = self.struts[i as usize].distance(q, r);
            d = if self.blend > 0.0 {
                smooth_min(d, di, self.blend)
            } else {
                d.min(di)
            };
        }
        d.min(self.reach)
    }

    /// The value at `p` at radius `r` (at most the radius the field was built for), its
    /// gradient in `p`, and the radius factor of the nearest struts (the value's slope against
    /// `r` is minus it). With sharp joins, the nearest strut's distance and gradient, from two
    /// passes over the struts of `p`'s bin instead of seven. Where struts tie for nearest
    /// (within the step central differences would take: on the mirror planes of a symmetric
    /// node, which the voxel grid often samples exactly) their gradients are averaged, as
    /// central differences average the one-sided slopes of a crease — so the result does not
    /// depend on the order the cell lists its struts in. (Blended joins are differentiated
    /// numerically, their factor the mean of the cell's.)
    pub fn gradient_at(&self, p: Vec3, r: f64) -> (f64, Vec3, f64) {
        if self.blend > 0.0 {
            let n = self.struts.len().max(1) as f64;
            let f = self.struts.iter().map(|s| 0.5 * (s.fa + s.fb)).sum::<f64>() / n;
            return (
                self.value_at(p, r),
                numeric_gradient(|q| self.value_at(q, r), p),
                f,
            );
        }
        let (q, bin) = self.locate(p);
        let near = &self.bins[bin];
        let d = near
            .iter()
            .map(|&i| self.struts[i as usize].distance(q, r))
            .fold(self.reach, f64::min);
        if d >= self.reach {
            // Beyond the reach the value is constant.
            return (self.reach, [0.0; 3], 0.0);
        }
        let tie = 1e-6 * (1.0 + p.iter().fold(0.0f64, |m, x| m.max(x.abs())));
        let (mut g, mut f, mut n) = ([0.0; 3], 0.0, 0.0);
        for &i in near {
            let s = &self.struts[i as usize];
            if s.distance(q, r) <= d + tie {
                let gi = s.gradient(q, r);
                g = [0, 1, 2].map(|a| g[a] + gi[a]);
                f += 0.5 * (s.fa + s.fb);
                n += 1.0;
            }
        }
        (d, g.map(|x| x / n), f / n)
    }

    /// The distance from `p` to the nearest strut axis, each over the strut's mean radius
    /// factor (up to the reach): the radius at which a capsule lattice first holds `p`.
    pub fn axis_distance(&self, p: Vec3) -> f64 {
        let (q, bin) = self.locate(p);
        self.bins[bin]
            .iter()
            .map(|&i| {
                let s = &self.struts[i as usize];
                let ap = sub(q, s.a);
                let t = (dot(ap, s.ab) / s.len2).clamp(0.0, 1.0);
                let d = sub(ap, scale(s.ab, t));
                dot(d, d).sqrt() / (0.5 * (s.fa + s.fb))
            })
            .fold(self.reach, f64::min)
    }

    /// The cell's centred coordinate along `axis` of the sample at `x`, and its bin.
    fn locate_axis(&self, x: f64, axis: usize) -> (f64, usize) {
        let s = self.cell[axis];
        let q = (x - self.origin[axis]).rem_euclid(s);
        let b = ((q / s * BINS as f64) as usize).min(BINS - 1);
        (q - 0.5 * s, b)
    }

    /// Struts of the augmented cell (the cell's own and the copies that reach into it).
    pub fn strut_count(&self) -> usize {
        self.struts.len()
    }

    /// The struts of the augmented cell, in the cell's centred coordinates (mm): their ends and
    /// the ends' radius factors.
    pub fn struts(&self) -> impl Iterator<Item = ([Vec3; 2], [f64; 2])> + '_ {
        self.struts
            .iter()
            .map(|s| ([s.a, add(s.a, s.ab)], [s.fa, s.fb]))
    }

    /// Per bin of the cell's index (bin `(i, j, k)` at `(i·BINS + j)·BINS + k`, bins splitting
    /// the cell into `BINS` equal parts along each axis), the [`StrutField::struts`] that come
    /// within reach of it.
    pub fn bins(&self) -> impl Iterator<Item = &[u32]> + '_ {
        self.bins.iter().map(Vec::as_slice)
    }

    /// The most struts one bin lists: what a sample looks at, at most.
    pub fn most_per_bin(&self) -> usize {
        self.bins.iter().map(Vec::len).max().unwrap_or(0)
    }

    /// `p` in the cell's centred coordinates, and its bin.
    fn locate(&self, p: Vec3) -> (Vec3, usize) {
        let [(x, i), (y, j), (z, k)] = [0, 1, 2].map(|a| self.locate_axis(p[a], a));
        ([x, y, z], (i * BINS + j) * BINS + k)
    }
}

impl Field for StrutField {
    fn value(&self, p: Vec3) -> f64 {
        self.value_at(p, self.radius)
    }

    fn clearance(&self, p: Vec3) -> f64 {
        self.value(p).abs()
    }

    fn value_and_clearance(&self, p: Vec3) -> (f64, f64) {
        let v = self.value(p);
        (v, v.abs())
    }

    /// See [`StrutField::gradient_at`].
    fn implicit_with_gradient(&self, p: Vec3) -> (f64, Vec3) {
        let (d, g, _) = self.gradient_at(p, self.radius);
        (d, g)
    }

    fn sample_block(&self, origin: Vec3, h: f64, out: &mut [f32; 512]) {
        self.sample_block_at(origin, h, out, |_, _, _| self.radius)
    }
}

impl StrutField {
    /// Samples the 8³ block at `origin`, spacing `h`, the sample `(i, j, k)` at radius
    /// `radius(i, j, k)` (at most the radius the field was built for).
    #[inline(always)]
    pub fn sample_block_at(
        &self,
        origin: Vec3,
        h: f64,
        out: &mut [f32; 512],
        radius: impl Fn(usize, usize, usize) -> f64,
    ) {
        let mut axes = [[(0.0, 0usize); 8]; 3];
        for (a, axis) in axes.iter_mut().enumerate() {
            let u = periodic::block_axis(
                self.samples_per_cell,
                self.origin[a],
                self.cell[a],
                origin[a],
                h,
                a,
            );
            for (slot, u) in axis.iter_mut().zip(u) {
                *slot = self.locate_axis(self.origin[a] + u * self.cell[a], a);
            }
        }
        for i in 0..8 {
            for j in 0..8 {
                for k in 0..8 {
                    let (q, bin) = (
                        [axes[0][i].0, axes[1][j].0, axes[2][k].0],
                        (axes[0][i].1 * BINS + axes[1][j].1) * BINS + axes[2][k].1,
                    );
                    out[(i * 8 + j) * 8 + k] = self.local_value(q, bin, radius(i, j, k)) as f32;
                }
            }
        }
    }
}

fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic generator (splitmix64) for the random points.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Every strut of a 5×5×5 block of cells (indices −2..=2 about the cell at `origin`), in mm.
    fn block(cell: &UnitCell, size: Vec3, origin: Vec3) -> Vec<Strut> {
        let mut all = Vec::new();
        for ([a, b], [fa, fb]) in cell.segments(size) {
            for n in 0..125 {
                let c = [n % 5, (n / 5) % 5, n / 25].map(|x| x as f64 - 2.0);
                let t = [0, 1, 2].map(|k| origin[k] + c[k] * size[k]);
                all.push(Strut::new(add(a, t), add(b, t), fa, fb));
            }
        }
        all
    }

    /// The value and gradient Newton uses equal the value and its central differences at random
    /// points of every built-in cell (capsules) and of a cell with rounded cones, away from the
    /// creases where two struts tie; at a point on a mirror plane of a node the gradient lies
    /// in that plane, as central differences put it.
    #[test]
    fn gradient_is_the_fields_slope() {
        let mut cells: Vec<(String, UnitCell)> = super::super::cell::BUILT_IN
            .iter()
            .map(|n| (n.to_string(), UnitCell::built_in(n).unwrap()))
            .collect();
        let mut cones = UnitCell::built_in("bcc").unwrap();
        cones.radii = (0..cones.nodes.len())
            .map(|i| 1.0 + 0.3 * (i % 2) as f64)
            .collect();
        cells.push(("bcc with cones".into(), cones));
        let (size, origin, radius, reach) = ([4.0, 5.0, 4.5], [-1.3, 0.7, 2.2], 0.35, 1.5);
        let mut rng = Rng(0x6ad);
        for (name, cell) in &cells {
            let f = StrutField::new(cell, size, origin, radius, 0.0, reach);
            let mut checked = 0;
            for _ in 0..4000 {
                let p = [0, 1, 2].map(|k| origin[k] + size[k] * (3.0 * rng.next() - 1.0));
                let (v, g) = f.implicit_with_gradient(p);
                assert_eq!(v, f.value(p), "{name} at {p:?}");
                // Away from creases (the two nearest struts farther apart than the step) and
                // from the reach, the slope is the nearest strut's.
                let (q, bin) = f.locate(p);
                let mut d: Vec<f64> = f.bins[bin]
                    .iter()
                    .map(|&i| f.struts[i as usize].distance(q, radius))
                    .collect();
                d.sort_by(f64::total_cmp);
                if d.len() < 2 || d[1] - d[0] < 1e-3 || d[0] > reach - 1e-3 {
                    continue;
                }
                let n = numeric_gradient(|x| f.value(x), p);
                let err = (0..3).map(|a| (g[a] - n[a]).abs()).fold(0.0, f64::max);
                assert!(
                    err < 1e-5,
                    "{name} at {p:?}: gradient {g:?}, central differences {n:?}"
                );
                checked += 1;
            }
            assert!(checked > 800, "{name}: only {checked} points checked");
        }
        // The bcc node at the cell's centre (2, 2, 2): on its mirror plane z = 2, the struts to
        // the corners above and below tie.
        let bcc = UnitCell::built_in("bcc").unwrap();
        let f = StrutField::new(&bcc, [4.0; 3], [0.0; 3], radius, 0.0, reach);
        let p = [2.3, 2.3, 2.0];
        let (_, g) = f.implicit_with_gradient(p);
        let n = numeric_gradient(|x| f.value(x), p);
        assert!(g[2].abs() < 1e-9, "{g:?} leaves the mirror plane z = 2");
        assert!(
            (0..3).all(|a| (g[a] - n[a]).abs() < 1e-5),
            "{g:?} against {n:?}"
        );
    }

    /// The per-cell evaluation with augmentation equals the distance to every strut of a 5×5×5
    /// lattice, brute force, at 10⁵ random points in its middle 3×3×3 cells, for every
    /// built-in cell and a custom cell whose struts cross faces, edges and corners. The
    /// comparison is clamped at the reach, which is below the distance from any point of the
    /// middle cells to a strut of a cell outside the block.
    #[test]
    fn one_cell_with_augmentation_is_the_whole_lattice() {
        // Loose struts (not one lattice: a cell file would be refused), for the evaluation only.
        let custom = UnitCell {
            nodes: vec![
                [0.9, 0.5, 0.5],
                [1.2, 0.5, 0.5],
                [0.8, 0.9, 0.5],
                [1.1, 1.3, 0.5],
                [0.85, 0.9, 0.95],
                [1.1, 1.05, 1.2],
                [0.1, 0.1, 0.1],
                [-0.15, 0.2, 0.3],
            ],
            struts: vec![[0, 1], [2, 3], [4, 5], [6, 7]],
            radii: vec![1.0, 1.5, 1.0, 1.0, 0.7, 1.3, 1.0, 1.0],
        }
        .canonical();
        let mut cells: Vec<(String, UnitCell)> = super::super::cell::BUILT_IN
            .iter()
            .map(|n| (n.to_string(), UnitCell::built_in(n).unwrap()))
            .collect();
        cells.push(("custom".into(), custom));
        let size = [4.0, 5.0, 4.5];
        let origin = [-1.3, 0.7, 2.2];
        let (radius, reach) = (0.35, 0.4);
        let mut rng = Rng(0x57a7);
        let points = 100_000 / cells.len() + 1;
        for (name, cell) in &cells {
            let f = StrutField::new(cell, size, origin, radius, 0.0, reach);
            let all = block(cell, size, origin);
            let mut inside = 0;
            for _ in 0..points {
                let p = [0, 1, 2].map(|k| origin[k] + size[k] * (3.0 * rng.next() - 1.0));
                let brute = all
                    .iter()
                    .map(|s| s.distance(p, radius))
                    .fold(f64::INFINITY, f64::min)
                    .min(reach);
                let v = f.value(p);
                assert!(
                    (v - brute).abs() < 1e-9,
                    "{name} at {p:?}: one cell gives {v}, the whole lattice {brute}"
                );
                inside += (v < 0.0) as usize;
            }
            assert!(inside > points / 100, "{name}: only {inside} points inside");
            assert!(
                f.most_per_bin() < f.strut_count() || f.strut_count() < 8,
                "{name}: the bins do not narrow the search"
            );
        }
    }

    /// A rounded cone's distance against a brute-force one: the minimum over a dense chain of
    /// spheres along the axis is the distance to their union, which tends to the cone's from
    /// above as the chain gets dense.
    #[test]
    fn rounded_cone_distance_matches_a_chain_of_spheres() {
        let s = Strut::new([0.0, 0.0, 0.0], [3.0, 1.0, -0.5], 0.8, 0.3);
        let (ra, rb) = (s.fa, s.fb);
        let mut rng = Rng(7);
        for _ in 0..2000 {
            let p = [0, 1, 2].map(|_| 6.0 * rng.next() - 2.0);
            // Spheres of the cone's ends, interpolated; their union is the rounded cone.
            let n = 20_000;
            let chain = (0..=n)
                .map(|i| {
                    let t = i as f64 / n as f64;
                    let c = scale(s.ab, t);
                    let r = ra + (rb - ra) * t;
                    dot(sub(p, c), sub(p, c)).sqrt() - r
                })
                .fold(f64::INFINITY, f64::min);
            let d = s.distance(p, 1.0);
            // The chain's union lies inside the cone: never below, and close above it.
            assert!(
                d <= chain + 1e-9 && chain - d < 2e-4,
                "{p:?}: {d} vs {chain}"
            );
        }
    }

    #[test]
    fn blending_fillets_joints_and_keeps_the_field_1_lipschitz() {
        let cell = UnitCell::built_in("bcc").unwrap();
        let sharp = StrutField::new(&cell, [5.0; 3], [0.0; 3], 0.4, 0.0, 1.0);
        let blended = StrutField::new(&cell, [5.0; 3], [0.0; 3], 0.4, 0.6, 1.0);
        // Near the centre node the blend adds material; far from any joint it changes nothing.
        let near_node = [2.5 + 0.45, 2.5, 2.5];
        assert!(blended.value(near_node) < sharp.value(near_node) - 0.01);
        let mid_strut = [1.25 + 0.3, 1.25, 1.25];
        assert!((blended.value(mid_strut) - sharp.value(mid_strut)).abs() < 1e-12);
        let mut rng = Rng(3);
        for _ in 0..20_000 {
            let p = [0, 1, 2].map(|_| 5.0 * rng.next());
            let d = [0, 1, 2].map(|_| 0.01 * (rng.next() - 0.5));
            let q = add(p, d);
            let lip = (blended.value(p) - blended.value(q)).abs() / dot(d, d).sqrt();
            assert!(lip <= 1.0 + 1e-6, "slope {lip} at {p:?}");
        }
    }

    /// Block sampling gives the values a point at a time gives; with index-periodic sampling,
    /// blocks a cell apart are bit-identical.
    #[test]
    fn block_sampling_matches_values_and_repeats_by_the_cell() {
        let cell = UnitCell::built_in("octet").unwrap();
        let h = 0.125;
        let origin = [0.3, -1.1, 2.0];
        let f = StrutField::new(&cell, [4.0; 3], origin, 0.4, 0.2, 3.0 * h);
        let start = [0, 1, 2].map(|a| origin[a] + 0.5 * h + 8.0 * h * 3.0);
        let mut block = [0.0f32; 512];
        f.sample_block(start, h, &mut block);
        for i in 0..8 {
            for j in 0..8 {
                for k in 0..8 {
                    let p = [
                        start[0] + h * i as f64,
                        start[1] + h * j as f64,
                        start[2] + h * k as f64,
                    ];
                    let v = block[(i * 8 + j) * 8 + k] as f64;
                    assert!((v - f.value(p)).abs() < 1e-6, "{p:?}");
                }
            }
        }
        let f = f.with_periodic_samples(h);
        let mut a = [0.0f32; 512];
        let mut b = [0.0f32; 512];
        f.sample_block(start, h, &mut a);
        f.sample_block([start[0] + 4.0 * 7.0, start[1] - 4.0, start[2]], h, &mut b);
        assert_eq!(a, b);
    }
}
