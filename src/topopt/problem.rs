//! Design problems: the mesh (a regular grid of unit elements), supports, loads and passive
//! elements. Built-in load cases and a small TOML problem-file format.
//!
//! Numbering follows the published codes so results can be compared entry by entry: elements
//! column by column (`e = iz·nelx·nely + ix·nely + row`), nodes likewise
//! (`n = iz·(nelx+1)(nely+1) + ix·(nely+1) + row`), with `row` counted from the **top** (MATLAB's
//! matrix rows), DOFs `d·n + axis`. Problem files and this module's helpers take coordinates
//! from the lower-left corner (`y` up) and convert.

use crate::error::{Error, Result};
use serde::Deserialize;
use std::path::Path;

/// What the elements carry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Physics {
    /// Linear elasticity (Q4 plane stress in 2D, H8 in 3D), E = 1, ν = 0.3.
    Elastic,
    /// Steady heat conduction (scalar, 2D), conductivity 1.
    Heat,
}

/// Element state fixed by the designer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Passive {
    /// Designed by the optimiser.
    Free,
    /// Kept void.
    Void,
    /// Kept solid.
    Solid,
}

/// A minimum-compliance design problem on a regular grid.
#[derive(Debug, Clone)]
pub struct Problem {
    /// The problem's name: a built-in's, or the problem file's path.
    pub name: String,
    /// Elements along x.
    pub nelx: usize,
    /// Elements along y.
    pub nely: usize,
    /// 0 for a 2D problem.
    pub nelz: usize,
    /// What the elements carry.
    pub physics: Physics,
    /// Fixed DOFs (any order, duplicates allowed).
    pub fixed: Vec<usize>,
    /// Nodal loads `(dof, value)`; repeated DOFs add up.
    pub loads: Vec<(usize, f64)>,
    /// Per element; empty means all free.
    pub passive: Vec<Passive>,
    /// Default volume fraction for this problem.
    pub volfrac: f64,
    /// Element edge length in mm, carried to the outputs.
    pub element_size: f64,
    /// Stiffness of void elements relative to solid (the codes' `Emin`).
    pub emin: f64,
}

impl Problem {
    /// Whether the problem is 3D (`nelz > 0`).
    pub fn is_3d(&self) -> bool {
        self.nelz > 0
    }

    /// Number of elements.
    pub fn elements(&self) -> usize {
        self.nelx * self.nely * self.nelz.max(1)
    }

    /// DOFs per node.
    pub fn dofs_per_node(&self) -> usize {
        match (self.physics, self.is_3d()) {
            (Physics::Heat, _) => 1,
            (Physics::Elastic, false) => 2,
            (Physics::Elastic, true) => 3,
        }
    }

    /// Number of nodes.
    pub fn nodes(&self) -> usize {
        (self.nelx + 1) * (self.nely + 1) * (self.nelz + 1)
    }

    /// Number of DOFs.
    pub fn dofs(&self) -> usize {
        self.nodes() * self.dofs_per_node()
    }

    /// Node at grid point `(ix, iy, iz)`, `iy` counted from the bottom.
    pub fn node(&self, ix: usize, iy: usize, iz: usize) -> usize {
        iz * (self.nelx + 1) * (self.nely + 1) + ix * (self.nely + 1) + (self.nely - iy)
    }

    /// Element at `(ix, row, iz)`, `row` counted from the top.
    pub fn element(&self, ix: usize, row: usize, iz: usize) -> usize {
        iz * self.nelx * self.nely + ix * self.nely + row
    }

    /// The element's DOFs in the element matrix's order (lower-left, lower-right, upper-right,
    /// upper-left; then the same on the far face in 3D).
    pub fn element_dofs(&self, e: usize, out: &mut Vec<usize>) {
        out.clear();
        let plane = self.nelx * self.nely;
        let iz = e / plane;
        let ix = (e % plane) / self.nely;
        let row = e % self.nely;
        let d = self.dofs_per_node();
        let n_ul = iz * (self.nelx + 1) * (self.nely + 1) + ix * (self.nely + 1) + row;
        let face = |base: usize, out: &mut Vec<usize>| {
            let ll = base + 1;
            let lr = base + 1 + self.nely + 1;
            let ur = base + self.nely + 1;
            for n in [ll, lr, ur, base] {
                for a in 0..d {
                    out.push(d * n + a);
                }
            }
        };
        face(n_ul, out);
        if self.is_3d() {
            face(n_ul + (self.nelx + 1) * (self.nely + 1), out);
        }
    }

    fn check(&self) -> Result<()> {
        if self.nelx == 0 || self.nely == 0 {
            return Err(Error::invalid(
                "the mesh needs at least one element per axis",
            ));
        }
        if self.elements() > 20_000_000 {
            return Err(Error::invalid(format!(
                "{} elements is beyond what the direct solver can handle here",
                self.elements()
            )));
        }
        if self.physics == Physics::Heat && self.is_3d() {
            return Err(Error::invalid("heat conduction problems are 2D only"));
        }
        let n = self.dofs();
        if self.fixed.iter().any(|&d| d >= n) || self.loads.iter().any(|&(d, _)| d >= n) {
            return Err(Error::invalid("a support or load lies outside the mesh"));
        }
        if self.fixed.is_empty() {
            return Err(Error::invalid(
                "the problem has no supports: the structure could move freely",
            ));
        }
        if self.loads.iter().all(|&(_, v)| v == 0.0) {
            return Err(Error::invalid("the problem has no load"));
        }
        if !self.passive.is_empty() && self.passive.len() != self.elements() {
            return Err(Error::invalid("passive element list has the wrong length"));
        }
        Ok(())
    }
}

/// The built-in load cases.
pub const BUILTIN: [&str; 5] = ["mbb", "cantilever", "lbeam", "heat", "cantilever3d"];

/// A built-in problem; `dims` overrides its default element counts (`nelz` only in 3D).
pub fn builtin(name: &str, dims: Option<[usize; 3]>) -> Result<Problem> {
    let name = name.to_ascii_lowercase();
    let (dflt, volfrac): ([usize; 3], f64) = match name.as_str() {
        "mbb" => ([60, 20, 0], 0.5),
        "cantilever" => ([30, 10, 0], 0.3),
        "lbeam" | "l-beam" => ([40, 40, 0], 0.3),
        "heat" => ([50, 50, 0], 0.3),
        "cantilever3d" => ([30, 10, 4], 0.3),
        _ => {
            return Err(Error::invalid(format!(
                "unknown problem '{name}' (built-in: {}; or a .toml problem file)",
                BUILTIN.join(", ")
            )))
        }
    };
    let [nelx, nely, mut nelz] = dims.unwrap_or(dflt);
    if name == "cantilever3d" && nelz == 0 {
        nelz = dflt[2];
    }
    if name != "cantilever3d" && nelz != 0 {
        return Err(Error::invalid(format!(
            "problem '{name}' is 2D; --nelz applies to cantilever3d or a 3D problem file"
        )));
    }
    let mut p = Problem {
        name: name.clone(),
        nelx,
        nely,
        nelz,
        physics: Physics::Elastic,
        fixed: Vec::new(),
        loads: Vec::new(),
        passive: Vec::new(),
        volfrac,
        element_size: 1.0,
        emin: 1e-9,
    };
    p.check_dims()?;
    match name.as_str() {
        // Half MBB beam (the 88-line code): symmetry line on the left (x fixed), roller at the
        // lower right, unit load down at the upper left.
        "mbb" => {
            p.fixed = (0..=nely).map(|r| 2 * r).collect();
            p.fixed.push(2 * p.nodes() - 1);
            p.loads = vec![(1, -1.0)];
        }
        // Liu et al. 2018's cantilever: left edge clamped, unit load down at the lower right
        // corner.
        "cantilever" => {
            p.fixed = (0..2 * (nely + 1)).collect();
            p.loads = vec![(2 * p.node(nelx, 0, 0) + 1, -1.0)];
            p.element_size = 4.0;
        }
        // L-bracket: the upper-right part (x > 0.4 L, y > 0.4 H) is void, the top of the
        // vertical arm is clamped, the load points down at the middle of the horizontal arm's end.
        "lbeam" | "l-beam" => {
            p.name = "lbeam".into();
            let (ax, ay) = ((nelx * 2).div_ceil(5), (nely * 2).div_ceil(5));
            p.passive = vec![Passive::Free; p.elements()];
            for ix in ax..nelx {
                for row in 0..nely - ay {
                    let e = p.element(ix, row, 0);
                    p.passive[e] = Passive::Void;
                }
            }
            for ix in 0..=ax {
                let n = p.node(ix, nely, 0);
                p.fixed.extend([2 * n, 2 * n + 1]);
            }
            p.loads = vec![(2 * p.node(nelx, ay / 2, 0) + 1, -1.0)];
        }
        // Heat conduction plate (the volume-to-point problem): uniform heat generation, all
        // edges insulated except a sink held at T = 0 at the middle of the left edge.
        "heat" => {
            p.physics = Physics::Heat;
            p.emin = 1e-3;
            let half = (nely / 20).max(1);
            p.fixed = (nely / 2 - half.min(nely / 2)..=(nely / 2 + half).min(nely))
                .map(|iy| p.node(0, iy, 0))
                .collect();
            p.loads = (0..p.nodes()).map(|n| (n, 0.01)).collect();
        }
        // top3d's default: left face clamped, a line load down along the lower right edge.
        _ => {
            for iz in 0..=nelz {
                for iy in 0..=nely {
                    let n = p.node(0, iy, iz);
                    p.fixed.extend([3 * n, 3 * n + 1, 3 * n + 2]);
                }
                p.loads.push((3 * p.node(nelx, 0, iz) + 1, -1.0));
            }
        }
    }
    p.check()?;
    Ok(p)
}

impl Problem {
    fn check_dims(&self) -> Result<()> {
        if self.nelx == 0 || self.nely == 0 {
            return Err(Error::invalid("element counts must be at least 1"));
        }
        Ok(())
    }
}

/// A problem file (TOML). Node ranges are inclusive grid coordinates from the lower-left corner
/// (in elements); element ranges are half-open.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ProblemFile {
    nelx: usize,
    nely: usize,
    #[serde(default)]
    nelz: usize,
    #[serde(default)]
    physics: Option<String>,
    #[serde(default)]
    volfrac: Option<f64>,
    #[serde(default)]
    element_size: Option<f64>,
    #[serde(default)]
    support: Vec<SupportSpec>,
    #[serde(default)]
    load: Vec<LoadSpec>,
    #[serde(default)]
    passive: Vec<PassiveSpec>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SupportSpec {
    x: [usize; 2],
    y: [usize; 2],
    #[serde(default)]
    z: Option<[usize; 2]>,
    /// Fixed directions: any of "x", "y", "z"; "t" (temperature) for heat problems.
    fix: String,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct LoadSpec {
    x: [usize; 2],
    y: [usize; 2],
    #[serde(default)]
    z: Option<[usize; 2]>,
    /// Per node: [fx, fy] or [fx, fy, fz]; one value (heat input) for heat problems.
    f: Vec<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PassiveSpec {
    x: [usize; 2],
    y: [usize; 2],
    #[serde(default)]
    z: Option<[usize; 2]>,
    solid: bool,
}

/// Reads a TOML problem file.
pub fn from_toml(path: &Path) -> Result<Problem> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    parse_toml(&text, &path.display().to_string()).map_err(|e| e.in_file(path))
}

/// Parses a TOML problem description (`name` labels the result).
pub fn parse_toml(text: &str, name: &str) -> Result<Problem> {
    let f: ProblemFile = toml::from_str(text).map_err(|e| Error::parse(e.message()))?;
    let physics = match f.physics.as_deref().unwrap_or("elastic") {
        "elastic" => Physics::Elastic,
        "heat" => Physics::Heat,
        other => {
            return Err(Error::parse(format!(
                "unknown physics '{other}' (elastic, heat)"
            )))
        }
    };
    let mut p = Problem {
        name: name.to_string(),
        nelx: f.nelx,
        nely: f.nely,
        nelz: f.nelz,
        physics,
        fixed: Vec::new(),
        loads: Vec::new(),
        passive: Vec::new(),
        volfrac: f.volfrac.unwrap_or(0.3),
        element_size: f.element_size.unwrap_or(1.0),
        emin: if physics == Physics::Heat { 1e-3 } else { 1e-9 },
    };
    if p.nelx == 0 || p.nely == 0 {
        return Err(Error::parse("nelx and nely must be at least 1"));
    }
    if !(p.volfrac > 0.0 && p.volfrac < 1.0) {
        return Err(Error::parse(format!(
            "volfrac must be in (0, 1), got {}",
            p.volfrac
        )));
    }
    if !(p.element_size > 0.0 && p.element_size.is_finite()) {
        return Err(Error::parse("element_size must be a positive length in mm"));
    }
    let d = p.dofs_per_node();
    let zmax = p.nelz;
    let g = p.clone();
    let nodes_in = |x: [usize; 2], y: [usize; 2], z: Option<[usize; 2]>, what: &str| {
        let z = z.unwrap_or([0, 0]);
        if x[0] > x[1] || y[0] > y[1] || z[0] > z[1] {
            return Err(Error::parse(format!(
                "{what}: a range [lo, hi] has lo > hi"
            )));
        }
        if x[1] > g.nelx || y[1] > g.nely || z[1] > zmax {
            return Err(Error::parse(format!(
                "{what}: node range beyond the {}×{}{} mesh",
                g.nelx,
                g.nely,
                if zmax > 0 {
                    format!("×{zmax}")
                } else {
                    String::new()
                }
            )));
        }
        let mut v = Vec::new();
        for iz in z[0]..=z[1] {
            for ix in x[0]..=x[1] {
                for iy in y[0]..=y[1] {
                    v.push(g.node(ix, iy, iz));
                }
            }
        }
        Ok(v)
    };
    for s in &f.support {
        let nodes = nodes_in(s.x, s.y, s.z, "support")?;
        for c in s.fix.chars() {
            let a = match (c, physics) {
                ('t', Physics::Heat) => 0,
                ('x', Physics::Elastic) => 0,
                ('y', Physics::Elastic) => 1,
                ('z', Physics::Elastic) if p.nelz > 0 => 2,
                (',' | ' ', _) => continue,
                _ => {
                    return Err(Error::parse(format!(
                        "support: cannot fix '{c}' in this problem"
                    )))
                }
            };
            p.fixed.extend(nodes.iter().map(|n| d * n + a));
        }
    }
    for l in &f.load {
        let nodes = nodes_in(l.x, l.y, l.z, "load")?;
        if l.f.len() != d || l.f.iter().any(|v| !v.is_finite()) {
            return Err(Error::parse(format!(
                "load: f needs {d} finite value(s) per node"
            )));
        }
        for n in nodes {
            for (a, &v) in l.f.iter().enumerate() {
                if v != 0.0 {
                    p.loads.push((d * n + a, v));
                }
            }
        }
    }
    if !f.passive.is_empty() {
        p.passive = vec![Passive::Free; p.elements()];
        for s in &f.passive {
            let z = s.z.unwrap_or([0, 1]);
            if s.x[1] > p.nelx || s.y[1] > p.nely || z[1] > p.nelz.max(1) {
                return Err(Error::parse("passive: element range beyond the mesh"));
            }
            for iz in z[0]..z[1] {
                for ix in s.x[0]..s.x[1] {
                    for iy in s.y[0]..s.y[1] {
                        let e = p.element(ix, p.nely - 1 - iy, iz);
                        p.passive[e] = if s.solid {
                            Passive::Solid
                        } else {
                            Passive::Void
                        };
                    }
                }
            }
        }
    }
    p.check().map_err(|e| Error::parse(e.to_string()))?;
    Ok(p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn element_dofs_match_the_88_line_edof_matrix() {
        // 88-line, nely = 2: element 1 (1-based) has edof [3 4 9 10 7 8 1 2] (1-based).
        let p = builtin("mbb", Some([3, 2, 0])).unwrap();
        let mut v = Vec::new();
        p.element_dofs(0, &mut v);
        assert_eq!(v, vec![2, 3, 8, 9, 6, 7, 0, 1]);
    }

    #[test]
    fn toml_problem_builds_a_cantilever() {
        let p = parse_toml(
            "nelx = 4\nnely = 2\n[[support]]\nx = [0, 0]\ny = [0, 2]\nfix = \"xy\"\n\
             [[load]]\nx = [4, 4]\ny = [0, 0]\nf = [0.0, -1.0]\n",
            "t",
        )
        .unwrap();
        let q = builtin("cantilever", Some([4, 2, 0])).unwrap();
        let mut a = p.fixed.clone();
        a.sort();
        assert_eq!(a, q.fixed);
        assert_eq!(p.loads, q.loads);
        assert!(parse_toml("nelx = 4\nnely = 2\n", "t").is_err());
        assert!(parse_toml("nelx = 4\nnely = 2\nbogus = 1\n", "t").is_err());
    }
}
