//! The seven triply periodic minimal surfaces of latvox, as trigonometric sums.
//!
//! Each surface is `F(X, Y, Z) = Σ c · t₁(k₁X) · t₂(k₂Y) · t₃(k₃Z)` with `X = 2π(x − x₀)/aₓ`
//! (period one cell) and `t ∈ {sin, cos}`, `k ∈ {0, 1, 2}`. Writing every surface in that one form
//! gives value, gradient and a Lipschitz bound from the same table, and lets a block of samples
//! share its sines and cosines along each axis.
//!
//! A *net* is the solid `F ≤ t`; a *sheet* is `|F| ≤ t`. The level-set value handed to OpenVDB is
//! the first-order distance `(F − t)/|∇F|` (resp. `(|F| − t)/|∇F|`), and the culling clearance is
//! `|F − t| / L` with `L ≥ max |∇F|`, which never overestimates the distance to the surface.

use crate::field::{periodic, Field, Vec3};
use std::f64::consts::TAU;

/// Which surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Surface {
    /// Schwarz primitive.
    P,
    /// Schoen gyroid.
    Gyroid,
    /// Schwarz diamond.
    D,
    /// Schoen I-WP.
    Iwp,
    /// Fischer–Koch S.
    S,
    /// Schoen F-RD.
    Frd,
    /// Neovius.
    Neovius,
    /// Lidinoid (Lidin and Larsson's approximation).
    Lidinoid,
    /// Schoen's split P (the nodal approximation).
    SplitP,
}

/// Which side of the surface is solid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Structure {
    /// Solid where `F ≤ t`.
    Net,
    /// Solid where `|F| ≤ t`: a wall of thickness set by `t` around the surface.
    Sheet,
    /// The net's other labyrinth: solid where `−F ≤ t` (`--side other`). Where the two sides of
    /// the surface differ (F-RD, I-WP, Neovius, …) it holds together at densities where the
    /// net does not.
    #[serde(rename = "net-other")]
    NetOther,
}

impl Structure {
    /// The structure's name on the command line and in reports (`net`, `sheet`).
    pub fn name(self) -> &'static str {
        match self {
            Structure::Net => "net",
            Structure::Sheet => "sheet",
            Structure::NetOther => "net-other",
        }
    }
}

impl Surface {
    /// Every surface.
    pub const ALL: [Surface; 9] = [
        Surface::P,
        Surface::Gyroid,
        Surface::D,
        Surface::Iwp,
        Surface::S,
        Surface::Frd,
        Surface::Neovius,
        Surface::Lidinoid,
        Surface::SplitP,
    ];

    /// The surface's name on the command line and in reports (`p`, `gyroid`, …).
    pub fn name(self) -> &'static str {
        match self {
            Surface::P => "p",
            Surface::Gyroid => "gyroid",
            Surface::D => "d",
            Surface::Iwp => "iwp",
            Surface::S => "s",
            Surface::Frd => "frd",
            Surface::Neovius => "neovius",
            Surface::Lidinoid => "lidinoid",
            Surface::SplitP => "split-p",
        }
    }

    /// Parses a full or short name (`g`, `gyroid`, `schwarz-p`, …), case-insensitively.
    pub fn parse(s: &str) -> Option<Surface> {
        Some(match s.to_ascii_lowercase().as_str() {
            "p" | "primitive" | "schwarz-p" => Surface::P,
            "g" | "gyroid" => Surface::Gyroid,
            "d" | "diamond" | "schwarz-d" => Surface::D,
            "i" | "iwp" | "i-wp" => Surface::Iwp,
            "s" | "fischer-koch-s" | "fks" => Surface::S,
            "f" | "frd" | "f-rd" => Surface::Frd,
            "n" | "neovius" => Surface::Neovius,
            "l" | "lidinoid" => Surface::Lidinoid,
            "split-p" | "splitp" | "split_p" => Surface::SplitP,
            _ => return None,
        })
    }

    /// `F(−u) = F(u)` (`Some(true)`: every term a product of cosines) or `F(−u) = −F(u)`
    /// (`Some(false)`: every term holds an odd number of sines).
    pub fn is_even(self) -> Option<bool> {
        let sines = |t: &Term| t.f.iter().filter(|f| f.1 == Trig::Sin).count();
        let terms = self.terms();
        if terms.iter().all(|t| sines(t) % 2 == 0) {
            Some(true)
        } else if terms.iter().all(|t| sines(t) % 2 == 1) {
            Some(false)
        } else {
            None
        }
    }

    pub(crate) fn terms(self) -> &'static [Term] {
        use Trig::{Cos as C, One as O, Sin as S};
        const fn t(coef: f64, f: [(u8, Trig); 3]) -> Term {
            Term { coef, f }
        }
        const P: &[Term] = &[
            t(-1.0, [(1, C), (0, O), (0, O)]),
            t(-1.0, [(0, O), (1, C), (0, O)]),
            t(-1.0, [(0, O), (0, O), (1, C)]),
        ];
        const G: &[Term] = &[
            t(1.0, [(1, C), (1, S), (0, O)]),
            t(1.0, [(0, O), (1, C), (1, S)]),
            t(1.0, [(1, S), (0, O), (1, C)]),
        ];
        const D: &[Term] = &[
            t(1.0, [(1, S), (1, S), (1, S)]),
            t(1.0, [(1, S), (1, C), (1, C)]),
            t(1.0, [(1, C), (1, S), (1, C)]),
            t(1.0, [(1, C), (1, C), (1, S)]),
        ];
        const IWP: &[Term] = &[
            t(2.0, [(1, C), (1, C), (0, O)]),
            t(2.0, [(0, O), (1, C), (1, C)]),
            t(2.0, [(1, C), (0, O), (1, C)]),
            t(-1.0, [(2, C), (0, O), (0, O)]),
            t(-1.0, [(0, O), (2, C), (0, O)]),
            t(-1.0, [(0, O), (0, O), (2, C)]),
        ];
        const FKS: &[Term] = &[
            t(1.0, [(2, C), (1, S), (1, C)]),
            t(1.0, [(1, C), (2, C), (1, S)]),
            t(1.0, [(1, S), (1, C), (2, C)]),
        ];
        const FRD: &[Term] = &[
            t(-4.0, [(1, C), (1, C), (1, C)]),
            t(1.0, [(2, C), (2, C), (0, O)]),
            t(1.0, [(0, O), (2, C), (2, C)]),
            t(1.0, [(2, C), (0, O), (2, C)]),
        ];
        const N: &[Term] = &[
            t(3.0, [(1, C), (0, O), (0, O)]),
            t(3.0, [(0, O), (1, C), (0, O)]),
            t(3.0, [(0, O), (0, O), (1, C)]),
            t(4.0, [(1, C), (1, C), (1, C)]),
        ];
        // ½(sin 2X cos Y sin Z + …) − ½(cos 2X cos 2Y + …) + 0.15.
        const L: &[Term] = &[
            t(0.5, [(2, S), (1, C), (1, S)]),
            t(0.5, [(1, S), (2, S), (1, C)]),
            t(0.5, [(1, C), (1, S), (2, S)]),
            t(-0.5, [(2, C), (2, C), (0, O)]),
            t(-0.5, [(0, O), (2, C), (2, C)]),
            t(-0.5, [(2, C), (0, O), (2, C)]),
            t(0.15, [(0, O), (0, O), (0, O)]),
        ];
        // 1.1(sin 2X sin Z cos Y + …) − 0.2(cos 2X cos 2Y + …) − 0.4(cos 2X + …).
        const SP: &[Term] = &[
            t(1.1, [(2, S), (1, C), (1, S)]),
            t(1.1, [(1, S), (2, S), (1, C)]),
            t(1.1, [(1, C), (1, S), (2, S)]),
            t(-0.2, [(2, C), (2, C), (0, O)]),
            t(-0.2, [(0, O), (2, C), (2, C)]),
            t(-0.2, [(2, C), (0, O), (2, C)]),
            t(-0.4, [(2, C), (0, O), (0, O)]),
            t(-0.4, [(0, O), (2, C), (0, O)]),
            t(-0.4, [(0, O), (0, O), (2, C)]),
        ];
        match self {
            Surface::P => P,
            Surface::Gyroid => G,
            Surface::D => D,
            Surface::Iwp => IWP,
            Surface::S => FKS,
            Surface::Frd => FRD,
            Surface::Neovius => N,
            Surface::Lidinoid => L,
            Surface::SplitP => SP,
        }
    }

    /// The terms of `F`, each `coef · Π_a f_a(k_a · 2π u_a)` as `(coef, [(k_a, f_a)])` with
    /// `f` 0 for 1, 1 for cos and 2 for sin: `F` for code that evaluates it elsewhere (the
    /// browser editor's shader).
    pub fn factors(self) -> Vec<(f64, [(u8, u8); 3])> {
        self.terms()
            .iter()
            .map(|t| {
                let code = |(k, trig): (u8, Trig)| {
                    let f = match trig {
                        Trig::One => 0,
                        Trig::Cos => 1,
                        Trig::Sin => 2,
                    };
                    (k, f)
                };
                (t.coef, t.f.map(code))
            })
            .collect()
    }

    /// `F` at cell coordinates `u` (one period per unit), with its gradient in `u`.
    pub fn eval(self, u: Vec3) -> (f64, Vec3) {
        let tabs = [
            AxisTable::at_turns(u[0]),
            AxisTable::at_turns(u[1]),
            AxisTable::at_turns(u[2]),
        ];
        let (v, g) = eval_terms(self.terms(), &tabs);
        (v, [g[0] * TAU, g[1] * TAU, g[2] * TAU])
    }

    /// `map(F, ∇F)` (gradient in cell coordinates) at the midpoints `(i + ½)/n` of an `n³` grid
    /// over the unit cell, in the order `(i·n + j)·n + k`; sines and cosines are taken once per
    /// axis.
    pub fn map_cell_midpoints<T: Send + Default + Clone>(
        self,
        n: usize,
        map: impl Fn(f64, Vec3) -> T + Sync,
    ) -> Vec<T> {
        use rayon::prelude::*;
        let tab: Vec<AxisTable> = (0..n)
            .map(|i| AxisTable::at_turns((i as f64 + 0.5) / n as f64))
            .collect();
        let terms = self.terms();
        let mut out = vec![T::default(); n * n * n];
        out.par_chunks_mut(n * n)
            .enumerate()
            .for_each(|(i, plane)| {
                for (j, row) in plane.chunks_exact_mut(n).enumerate() {
                    for (k, o) in row.iter_mut().enumerate() {
                        let (v, g) = eval_terms(terms, &[tab[i], tab[j], tab[k]]);
                        *o = map(v, g.map(|x| x * TAU));
                    }
                }
            });
        out
    }

    /// Bounds on `|∂F/∂u_a|` per axis (cell coordinates).
    pub fn lipschitz_per_axis(self) -> Vec3 {
        let mut l = [0.0; 3];
        for term in self.terms() {
            for (a, la) in l.iter_mut().enumerate() {
                *la += term.coef.abs() * term.f[a].0 as f64 * TAU;
            }
        }
        l
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Trig {
    One,
    Cos,
    Sin,
}

#[derive(Debug, Clone, Copy)]
pub(crate) struct Term {
    coef: f64,
    f: [(u8, Trig); 3],
}

/// sin and cos of X and 2X at one coordinate, with their derivatives by X.
#[derive(Clone, Copy, Default)]
struct AxisTable {
    s1: f64,
    c1: f64,
    s2: f64,
    c2: f64,
}

impl AxisTable {
    /// At `X = 2π·u`.
    #[inline(always)]
    fn at_turns(u: f64) -> Self {
        let (s1, c1) = sin_cos_turns(u);
        AxisTable {
            s1,
            c1,
            s2: 2.0 * s1 * c1,
            c2: c1 * c1 - s1 * s1,
        }
    }

    /// (value, derivative) of `trig(k·X)`.
    #[inline(always)]
    fn factor(&self, k: u8, trig: Trig) -> (f64, f64) {
        match (trig, k) {
            (Trig::One, _) | (_, 0) => (if trig == Trig::Sin { 0.0 } else { 1.0 }, 0.0),
            (Trig::Cos, 1) => (self.c1, -self.s1),
            (Trig::Sin, 1) => (self.s1, self.c1),
            (Trig::Cos, _) => (self.c2, -2.0 * self.s2),
            (Trig::Sin, _) => (self.s2, 2.0 * self.c2),
        }
    }
}

/// `(sin 2πu, cos 2πu)`, for `|u| < 2⁵¹`. The period is taken off `u` exactly (`u − round(u)`) and the rest
/// reduced to an eighth of a turn by quarter turns (exact), so the angle the polynomials see is
/// at most π/4 and carries one rounding, however many cells from the origin `u` lies; the
/// polynomials are fdlibm's `__kernel_sin`/`__kernel_cos` (error below one ulp there). Faster
/// than the C library's `sincos`, which reduces an arbitrary angle and guards the rounding mode.
#[inline(always)]
pub(crate) fn sin_cos_turns(u: f64) -> (f64, f64) {
    // Nearest integer by the 1.5·2⁵² trick (exact below 2⁵¹; `f64::round` is a library call
    // on the x86-64 baseline).
    const M: f64 = 6_755_399_441_055_744.0;
    let r = u - ((u + M) - M);
    let q = (4.0 * r + M) - M;
    let x = TAU * (r - 0.25 * q);
    let z = x * x;
    let s = x + x
        * z
        * (-1.666_666_666_666_663_2e-1
            + z * (8.333_333_333_322_49e-3
                + z * (-1.984_126_982_985_795e-4
                    + z * (2.755_731_370_707_006_8e-6
                        + z * (-2.505_076_025_340_686_3e-8 + z * 1.589_690_995_211_55e-10)))));
    let c = 1.0 - 0.5 * z
        + z * z
            * (4.166_666_666_666_66e-2
                + z * (-1.388_888_888_887_411e-3
                    + z * (2.480_158_728_947_673e-5
                        + z * (-2.755_731_435_139_066_3e-7
                            + z * (2.087_572_321_298_175e-9 + z * -1.135_964_755_778_819_5e-11)))));
    match q as i64 & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

#[inline(always)]
fn eval_terms(terms: &[Term], tabs: &[AxisTable; 3]) -> (f64, Vec3) {
    let mut v = 0.0;
    let mut g = [0.0; 3];
    for term in terms {
        let (a, da) = tabs[0].factor(term.f[0].0, term.f[0].1);
        let (b, db) = tabs[1].factor(term.f[1].0, term.f[1].1);
        let (c, dc) = tabs[2].factor(term.f[2].0, term.f[2].1);
        v += term.coef * a * b * c;
        g[0] += term.coef * da * b * c;
        g[1] += term.coef * a * db * c;
        g[2] += term.coef * a * b * dc;
    }
    (v, g)
}

/// A TPMS lattice filling all space: surface, structure, level, cell size and phase origin.
#[derive(Debug, Clone, Copy)]
pub struct TpmsField {
    /// Which surface.
    pub surface: Surface,
    /// Which side of it is solid.
    pub structure: Structure,
    /// The level `t`.
    pub level: f64,
    /// Cell size per axis, mm.
    pub cell: Vec3,
    /// A lattice point (phase), mm.
    pub origin: Vec3,
    /// Values are clamped to ±`clamp` (the narrow band's background value).
    pub clamp: f64,
    /// Samples per cell along each axis where a cell holds a whole number of samples (0 on an
    /// axis where it does not): block sampling then takes each sample's phase along that axis
    /// from its index modulo this count, so samples one cell apart are bit-identical and a
    /// periodic lattice meshes identically in every cell along it. (The counts and the voxel
    /// size they were made for; `None` when no axis qualifies.)
    pub samples_per_cell: Option<([u32; 3], f64)>,
    lipschitz: f64,
}

impl TpmsField {
    /// The lattice of `surface` and `structure` at `level`, with cells of size `cell` (mm) and
    /// a lattice point at `origin` (mm); values clamped to ±`clamp`.
    pub fn new(
        surface: Surface,
        structure: Structure,
        level: f64,
        cell: Vec3,
        origin: Vec3,
        clamp: f64,
    ) -> Self {
        let l = surface.lipschitz_per_axis();
        let lipschitz =
            ((l[0] / cell[0]).powi(2) + (l[1] / cell[1]).powi(2) + (l[2] / cell[2]).powi(2)).sqrt();
        TpmsField {
            surface,
            structure,
            level,
            cell,
            origin,
            clamp,
            samples_per_cell: None,
            lipschitz,
        }
    }

    /// Turns on index-periodic block sampling along each axis where a cell spans a whole number
    /// of voxels `h`.
    pub fn with_periodic_samples(mut self, h: f64) -> Self {
        self.samples_per_cell = periodic::samples_per_cell(self.cell, h);
        self
    }

    /// The implicit function whose zero set is the surface: `F − t` or `|F| − t`.
    #[inline(always)]
    fn implicit(&self, f: f64) -> f64 {
        self.implicit_at(f, self.level)
    }

    /// The implicit function at level `t`.
    #[inline(always)]
    pub(crate) fn implicit_at(&self, f: f64, t: f64) -> f64 {
        match self.structure {
            Structure::Net => f - t,
            Structure::Sheet => f.abs() - t,
            Structure::NetOther => -f - t,
        }
    }

    #[inline(always)]
    fn distance(&self, f: f64, g_cell: Vec3) -> f64 {
        self.distance_at(f, g_cell, self.level)
    }

    /// The first-order distance to the surface at level `t` from `F` and its gradient in cell
    /// coordinates, clamped to the band.
    #[inline(always)]
    pub(crate) fn distance_at(&self, f: f64, g_cell: Vec3, t: f64) -> f64 {
        let g = [
            g_cell[0] / self.cell[0],
            g_cell[1] / self.cell[1],
            g_cell[2] / self.cell[2],
        ];
        let norm = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
        let v = self.implicit_at(f, t);
        let d = if norm > 1e-12 {
            v / norm
        } else {
            v.signum() * self.clamp
        };
        d.clamp(-self.clamp, self.clamp)
    }

    /// `F` and its gradient in cell coordinates at a world point.
    pub(crate) fn eval_at(&self, p: Vec3) -> (f64, Vec3) {
        self.surface.eval(self.cell_coords(p))
    }

    /// The surface's Lipschitz bound in world units (`|∇F|` per mm at most).
    pub(crate) fn lipschitz(&self) -> f64 {
        self.lipschitz
    }

    /// Samples a block as [`Field::sample_block`] does, at a level that may vary from sample to
    /// sample: `level(i, j, k)` for the sample `origin + h·(i, j, k)`.
    #[inline(always)]
    pub(crate) fn sample_block_at(
        &self,
        origin: Vec3,
        h: f64,
        out: &mut [f32; 512],
        level: impl Fn(usize, usize, usize) -> f64,
    ) {
        let mut tabs = [[AxisTable::default(); 8]; 3];
        for (a, tab) in tabs.iter_mut().enumerate() {
            let u = periodic::block_axis(
                self.samples_per_cell,
                self.origin[a],
                self.cell[a],
                origin[a],
                h,
                a,
            );
            for (t, u) in tab.iter_mut().zip(u) {
                *t = AxisTable::at_turns(u);
            }
        }
        let terms = self.surface.terms();
        for i in 0..8 {
            for j in 0..8 {
                for k in 0..8 {
                    let (f, g) = eval_terms(terms, &[tabs[0][i], tabs[1][j], tabs[2][k]]);
                    let g = [g[0] * TAU, g[1] * TAU, g[2] * TAU];
                    out[(i * 8 + j) * 8 + k] = self.distance_at(f, g, level(i, j, k)) as f32;
                }
            }
        }
    }

    fn cell_coords(&self, p: Vec3) -> Vec3 {
        [
            (p[0] - self.origin[0]) / self.cell[0],
            (p[1] - self.origin[1]) / self.cell[1],
            (p[2] - self.origin[2]) / self.cell[2],
        ]
    }

    /// The raw `F` at a world point.
    pub fn raw(&self, p: Vec3) -> f64 {
        self.surface.eval(self.cell_coords(p)).0
    }
}

impl Field for TpmsField {
    fn value(&self, p: Vec3) -> f64 {
        let (f, g) = self.surface.eval(self.cell_coords(p));
        self.distance(f, g)
    }

    fn clearance(&self, p: Vec3) -> f64 {
        self.implicit(self.raw(p)).abs() / self.lipschitz
    }

    fn value_and_clearance(&self, p: Vec3) -> (f64, f64) {
        let (f, g) = self.surface.eval(self.cell_coords(p));
        (self.distance(f, g), self.implicit(f).abs() / self.lipschitz)
    }

    fn implicit_with_gradient(&self, p: Vec3) -> (f64, Vec3) {
        let (f, g) = self.surface.eval(self.cell_coords(p));
        let sign = match self.structure {
            Structure::Net => 1.0,
            Structure::Sheet => f.signum(),
            Structure::NetOther => -1.0,
        };
        (
            self.implicit(f),
            [0, 1, 2].map(|a| sign * g[a] / self.cell[a]),
        )
    }

    fn sample_block(&self, origin: Vec3, h: f64, out: &mut [f32; 512]) {
        self.sample_block_at(origin, h, out, |_, _, _| self.level)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The published formulas (period 1), written out directly, as an independent reference.
    fn reference(s: Surface, u: Vec3) -> f64 {
        let (x, y, z) = (TAU * u[0], TAU * u[1], TAU * u[2]);
        let (c, sn) = (f64::cos, f64::sin);
        match s {
            Surface::P => -(c(x) + c(y) + c(z)),
            Surface::Gyroid => c(x) * sn(y) + c(y) * sn(z) + c(z) * sn(x),
            Surface::D => {
                sn(x) * sn(y) * sn(z)
                    + sn(x) * c(y) * c(z)
                    + c(x) * sn(y) * c(z)
                    + c(x) * c(y) * sn(z)
            }
            Surface::Iwp => {
                2.0 * (c(x) * c(y) + c(y) * c(z) + c(z) * c(x))
                    - (c(2.0 * x) + c(2.0 * y) + c(2.0 * z))
            }
            Surface::S => {
                c(2.0 * x) * sn(y) * c(z) + c(x) * c(2.0 * y) * sn(z) + sn(x) * c(y) * c(2.0 * z)
            }
            Surface::Frd => {
                -(4.0 * c(x) * c(y) * c(z)
                    - (c(2.0 * x) * c(2.0 * y) + c(2.0 * y) * c(2.0 * z) + c(2.0 * z) * c(2.0 * x)))
            }
            Surface::Neovius => 3.0 * (c(x) + c(y) + c(z)) + 4.0 * c(x) * c(y) * c(z),
            Surface::Lidinoid => {
                0.5 * (sn(2.0 * x) * c(y) * sn(z)
                    + sn(2.0 * y) * c(z) * sn(x)
                    + sn(2.0 * z) * c(x) * sn(y))
                    - 0.5
                        * (c(2.0 * x) * c(2.0 * y)
                            + c(2.0 * y) * c(2.0 * z)
                            + c(2.0 * z) * c(2.0 * x))
                    + 0.15
            }
            Surface::SplitP => {
                1.1 * (sn(2.0 * x) * sn(z) * c(y)
                    + sn(2.0 * y) * sn(x) * c(z)
                    + sn(2.0 * z) * sn(y) * c(x))
                    - 0.2
                        * (c(2.0 * x) * c(2.0 * y)
                            + c(2.0 * y) * c(2.0 * z)
                            + c(2.0 * z) * c(2.0 * x))
                    - 0.4 * (c(2.0 * x) + c(2.0 * y) + c(2.0 * z))
            }
        }
    }

    fn points() -> Vec<Vec3> {
        (0..50)
            .map(|i| {
                let f = i as f64;
                [
                    (f * 0.137).fract(),
                    (f * 0.311 + 0.05).fract(),
                    (f * 0.713 + 0.3).fract(),
                ]
            })
            .collect()
    }

    #[test]
    fn sin_cos_turns_matches_the_c_library() {
        let mut worst = 0.0f64;
        for i in 0..200_000 {
            // Quarter- and half-turn multiples, their neighbours, and far from the origin.
            let u = match i % 4 {
                0 => (i as f64) * 1e-4 - 10.0,
                1 => (i / 4) as f64 * 0.125 - 500.0,
                2 => ((i / 4) as f64 * 0.25).next_up(),
                _ => (i as f64).sqrt() * 37.3 - 3000.0,
            };
            let (s, c) = sin_cos_turns(u);
            // The reference reduces the period exactly too, so that both see the same angle.
            let (rs, rc) = (TAU * (u - u.round())).sin_cos();
            worst = worst.max((s - rs).abs()).max((c - rc).abs());
            assert!((s * s + c * c - 1.0).abs() < 1e-15, "{u}");
        }
        assert!(worst < 4e-16, "largest difference {worst:e}");
    }

    #[test]
    fn values_match_the_published_formulas() {
        for s in Surface::ALL {
            for u in points() {
                let (v, _) = s.eval(u);
                assert!((v - reference(s, u)).abs() < 1e-12, "{s:?} at {u:?}");
            }
        }
    }

    #[test]
    fn gradients_match_finite_differences() {
        let e = 1e-6;
        for s in Surface::ALL {
            for u in points() {
                let (_, g) = s.eval(u);
                for a in 0..3 {
                    let (mut up, mut dn) = (u, u);
                    up[a] += e;
                    dn[a] -= e;
                    let fd = (reference(s, up) - reference(s, dn)) / (2.0 * e);
                    assert!(
                        (g[a] - fd).abs() < 1e-5 * (1.0 + fd.abs()),
                        "{s:?} axis {a}"
                    );
                }
            }
        }
    }

    #[test]
    fn every_surface_fits_the_editor_shader() {
        // trace.glsl holds 10 terms (uTerms[10]).
        for s in Surface::ALL {
            assert!(s.terms().len() <= 10, "{s:?}");
        }
    }

    #[test]
    fn lipschitz_bound_holds_on_samples() {
        for s in Surface::ALL {
            let l = s.lipschitz_per_axis();
            for u in points() {
                let (_, g) = s.eval(u);
                for a in 0..3 {
                    assert!(g[a].abs() <= l[a] + 1e-9, "{s:?}");
                }
            }
        }
    }

    #[test]
    fn periodic_sampling_repeats_bit_for_bit_and_agrees_with_world_sampling() {
        let h = 5.0 / 32.0;
        let phase = [1.0, -2.0, 0.5];
        let f = TpmsField::new(Surface::Gyroid, Structure::Net, 0.2, [5.0; 3], phase, 1.0);
        let periodic = f.with_periodic_samples(h);
        assert_eq!(periodic.samples_per_cell, Some(([32; 3], h)));
        let at = |field: &TpmsField, block: [f64; 3]| {
            let mut out = [0.0f32; 512];
            let o = [0, 1, 2].map(|a| phase[a] + (block[a] * 8.0 + 0.5) * h);
            field.sample_block(o, h, &mut out);
            out
        };
        for b in [[0.0, 0.0, 0.0], [1.0, 3.0, -2.0]] {
            let here = at(&periodic, b);
            // Three cells further along x and one back along z: 12 and −4 blocks of 8 samples.
            let there = at(&periodic, [b[0] + 12.0, b[1], b[2] - 4.0]);
            assert_eq!(here, there);
            let world = at(&f, b);
            for (p, w) in here.iter().zip(world.iter()) {
                assert!((p - w).abs() < 1e-5, "{p} vs {w}");
            }
        }
        // A cell that is not a whole number of voxels gets no periodic sampling; one that is
        // along some axes only gets it along those.
        assert_eq!(f.with_periodic_samples(5.0 / 31.5).samples_per_cell, None);
        let g = TpmsField::new(
            Surface::Gyroid,
            Structure::Net,
            0.2,
            [5.0, 5.0, 4.0],
            phase,
            1.0,
        );
        let mixed = g.with_periodic_samples(0.16);
        assert_eq!(mixed.samples_per_cell, Some(([0, 0, 25], 0.16)));
        let at_mixed = |block: [f64; 3]| {
            let mut out = [0.0f32; 512];
            let o = [0, 1, 2].map(|a| phase[a] + (block[a] * 8.0 + 0.5) * 0.16);
            mixed.sample_block(o, 0.16, &mut out);
            out
        };
        // 25 samples per cell along z: 200 samples, 25 blocks, are 8 cells.
        assert_eq!(at_mixed([1.0, 2.0, 0.0]), at_mixed([1.0, 2.0, 25.0]));
    }

    #[test]
    fn block_sampling_agrees_with_pointwise_values() {
        let f = TpmsField::new(
            Surface::S,
            Structure::Sheet,
            0.3,
            [5.0, 4.0, 6.0],
            [0.1, 0.2, 0.3],
            1.0,
        );
        let mut block = [0.0f32; 512];
        let (o, h) = ([1.0, -2.0, 0.5], 0.13);
        f.sample_block(o, h, &mut block);
        for i in 0..8 {
            for j in 0..8 {
                for k in 0..8 {
                    let p = [
                        o[0] + h * i as f64,
                        o[1] + h * j as f64,
                        o[2] + h * k as f64,
                    ];
                    assert!((block[(i * 8 + j) * 8 + k] as f64 - f.value(p)).abs() < 1e-5);
                }
            }
        }
    }
}
