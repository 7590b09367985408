//! Unit cells of struts: nodes in unit-cell coordinates (`[0, 1]³` for the built-in cells), struts
//! as node pairs, and an optional radius factor per node (a strut between nodes of different
//! factors is a cone with rounded ends).
//!
//! A cell describes one period of the lattice: a strut and its translates by whole cells are the
//! same strut, so the cell is stored in a canonical form ([`UnitCell::canonical`]) in which each
//! strut appears once, with its midpoint in `[0, 1)³`. The built-in cells are drawn whole (all
//! twelve edges of `sc`'s cube, say); the canonical form keeps one of each set of translates.

use crate::error::{Error, Result};
use crate::field::Vec3;
use serde::Deserialize;
use std::path::Path;

/// A unit cell of struts.
#[derive(Debug, Clone, PartialEq)]
pub struct UnitCell {
    /// Node positions in unit-cell coordinates.
    pub nodes: Vec<Vec3>,
    /// Struts as pairs of node indices.
    pub struts: Vec<[usize; 2]>,
    /// Radius factor per node (the strut radius times this at the node); 1 for every node when
    /// the cell does not give them.
    pub radii: Vec<f64>,
}

/// The built-in cells, by name.
pub const BUILT_IN: [&str; 9] = [
    "sc", "bcc", "bccz", "fcc", "fccz", "octet", "kelvin", "diamond", "rhombic",
];

/// The cube's corners, `i`'s bits giving x, y, z.
fn corner(i: usize) -> Vec3 {
    [i & 1, (i >> 1) & 1, (i >> 2) & 1].map(|b| b as f64)
}

/// The cube's twelve edges, as corner pairs.
fn cube_edges() -> Vec<[Vec3; 2]> {
    let mut e = Vec::new();
    for i in 0..8 {
        for a in 0..3 {
            if i & (1 << a) == 0 {
                e.push([corner(i), corner(i | (1 << a))]);
            }
        }
    }
    e
}

/// The four edges along z.
fn vertical_edges() -> Vec<[Vec3; 2]> {
    (0..4)
        .map(|i| [corner(i), corner(i | 4)])
        .collect::<Vec<_>>()
}

/// From the centre to the eight corners.
fn body_diagonals() -> Vec<[Vec3; 2]> {
    (0..8).map(|i| [[0.5; 3], corner(i)]).collect()
}

/// The two diagonals of each of the six faces, as four struts from the corners to the face's
/// centre (a node where the diagonals cross).
fn face_diagonals() -> Vec<[Vec3; 2]> {
    let mut e = Vec::new();
    for a in 0..3 {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        for side in [0.0, 1.0] {
            let p = |u: f64, v: f64| {
                let mut q = [0.0; 3];
                q[a] = side;
                q[b] = u;
                q[c] = v;
                q
            };
            for (u, v) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
                e.push([p(u, v), p(0.5, 0.5)]);
            }
        }
    }
    e
}

/// Between face centres that are not opposite: the octahedron of the octet truss.
fn octahedron() -> Vec<[Vec3; 2]> {
    let centres: Vec<Vec3> = (0..3)
        .flat_map(|a| {
            [0.0, 1.0].map(|side| {
                let mut q = [0.5; 3];
                q[a] = side;
                q
            })
        })
        .collect();
    let mut e = Vec::new();
    for i in 0..6 {
        for j in i + 1..6 {
            if i / 2 != j / 2 {
                e.push([centres[i], centres[j]]);
            }
        }
    }
    e
}

/// Pairs of `points` at distance `d` (to 1e-9): the edges of a polyhedron given its vertices
/// and edge length.
fn edges_at(points: &[Vec3], d: f64) -> Vec<[Vec3; 2]> {
    let mut e = Vec::new();
    for i in 0..points.len() {
        for j in i + 1..points.len() {
            if (dist(points[i], points[j]) - d).abs() < 1e-9 {
                e.push([points[i], points[j]]);
            }
        }
    }
    e
}

fn dist(a: Vec3, b: Vec3) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt()
}

/// An integer lattice given by generators, kept in echelon form (Hermite's normal form, up to
/// the rows' signs), to tell its rank and index in Z³.
#[derive(Default)]
struct IntegerLattice {
    /// Row `k`, when present, has its first nonzero entry in column `k`.
    rows: [Option<[i64; 3]>; 3],
}

impl IntegerLattice {
    /// Adds a generator.
    fn add(&mut self, mut v: [i64; 3]) {
        for k in 0..3 {
            if v[k] == 0 {
                continue;
            }
            let Some(mut row) = self.rows[k] else {
                self.rows[k] = Some(v);
                return;
            };
            // Euclid on the column-k entries of the row and v, carrying the whole vectors.
            while v[k] != 0 {
                let q = row[k].div_euclid(v[k]);
                let r = [0, 1, 2].map(|c| row[c] - q * v[c]);
                row = v;
                v = r;
            }
            self.rows[k] = Some(row);
        }
    }

    /// The index of the lattice in Z³ (how many cosets), or `None` below rank 3.
    fn index(&self) -> Option<u64> {
        let mut d = 1u64;
        for k in 0..3 {
            d *= self.rows[k]?[k].unsigned_abs();
        }
        Some(d)
    }
}

/// The truncated octahedron of the body-centred packing (Kelvin's cell): the 24 points
/// `(½, ½, ½) + (0, ±¼, ±½)` in every order of the axes, joined at distance √2/4.
fn kelvin() -> Vec<[Vec3; 2]> {
    let mut pts = Vec::new();
    for perm in [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ] {
        for s1 in [-1.0, 1.0] {
            for s2 in [-1.0, 1.0] {
                let v = [0.0, 0.25 * s1, 0.5 * s2];
                pts.push([0, 1, 2].map(|a| 0.5 + v[perm[a]]));
            }
        }
    }
    edges_at(&pts, 2f64.sqrt() / 4.0)
}

/// Diamond cubic: each atom of the face-centred sites shifted by (¼, ¼, ¼) bonded to its four
/// neighbours on the unshifted sites.
fn diamond() -> Vec<[Vec3; 2]> {
    let fcc = [
        [0.0, 0.0, 0.0],
        [0.0, 0.5, 0.5],
        [0.5, 0.0, 0.5],
        [0.5, 0.5, 0.0],
    ];
    let bonds = [
        [-0.25, -0.25, -0.25],
        [0.25, 0.25, -0.25],
        [0.25, -0.25, 0.25],
        [-0.25, 0.25, 0.25],
    ];
    let mut e = Vec::new();
    for f in fcc {
        let a = f.map(|x| x + 0.25);
        for b in bonds {
            e.push([a, [0, 1, 2].map(|k| a[k] + b[k])]);
        }
    }
    e
}

/// The rhombic dodecahedra of the face-centred packing: each tetrahedral hole `(¼ or ¾)³`
/// joined to the four octahedral holes (the cell's centre and its edges' midpoints) a
/// `(±¼, ±¼, ±¼)` step away.
fn rhombic() -> Vec<[Vec3; 2]> {
    let mut e = Vec::new();
    for i in 0..8 {
        let t = corner(i).map(|b| 0.25 + 0.5 * b);
        for s in 0..8 {
            let q = [0, 1, 2].map(|a| t[a] + if s & (1 << a) != 0 { 0.25 } else { -0.25 });
            let halves = q.iter().filter(|&&x| (x - 0.5).abs() < 1e-12).count();
            if halves == 1 || halves == 3 {
                e.push([t, q]);
            }
        }
    }
    e
}

impl UnitCell {
    /// The smallest radius factor: the thinnest strut is the radius times it.
    pub fn thinnest_factor(&self) -> f64 {
        self.radii.iter().cloned().fold(f64::INFINITY, f64::min)
    }

    /// A built-in cell by name (see [`BUILT_IN`]).
    pub fn built_in(name: &str) -> Result<UnitCell> {
        let segments = match name {
            "sc" => cube_edges(),
            "bcc" => body_diagonals(),
            "bccz" => [body_diagonals(), vertical_edges()].concat(),
            "fcc" => face_diagonals(),
            "fccz" => [face_diagonals(), vertical_edges()].concat(),
            "octet" => [face_diagonals(), octahedron()].concat(),
            "kelvin" => kelvin(),
            "diamond" => diamond(),
            "rhombic" => rhombic(),
            _ => {
                return Err(Error::invalid(format!(
                    "unknown cell '{name}' (built in: {}; or a cell file, .json)",
                    BUILT_IN.join(", ")
                )))
            }
        };
        Ok(UnitCell::from_segments(&segments).canonical())
    }

    /// A cell from struts given by their end points, nodes shared where the points coincide.
    pub fn from_segments(segments: &[[Vec3; 2]]) -> UnitCell {
        let mut cell = UnitCell {
            nodes: Vec::new(),
            struts: Vec::new(),
            radii: Vec::new(),
        };
        for s in segments {
            let ends = s.map(|p| cell.node(p, 1.0));
            cell.struts.push(ends);
        }
        cell
    }

    /// The index of the node at `p` with radius factor `r`, added if there is none.
    fn node(&mut self, p: Vec3, r: f64) -> usize {
        match self
            .nodes
            .iter()
            .zip(&self.radii)
            .position(|(q, &rq)| dist(*q, p) < 1e-9 && (rq - r).abs() < 1e-12)
        {
            Some(i) => i,
            None => {
                self.nodes.push(p);
                self.radii.push(r);
                self.nodes.len() - 1
            }
        }
    }

    /// The cell with each strut once: translated by whole cells so its midpoint lies in
    /// `[0, 1)³`, its ends ordered, repeats (a strut and its translates, the same strut twice)
    /// dropped, struts of zero length dropped.
    pub fn canonical(&self) -> UnitCell {
        let mut out = UnitCell {
            nodes: Vec::new(),
            struts: Vec::new(),
            radii: Vec::new(),
        };
        let mut seen = std::collections::HashSet::new();
        for &[i, j] in &self.struts {
            let (a, b) = (self.nodes[i], self.nodes[j]);
            if dist(a, b) < 1e-9 {
                continue;
            }
            // Rounding the midpoint before the floor keeps a midpoint on a cell face (½ of a
            // sum of exact unit coordinates) from landing on either side by rounding.
            let shift = [0, 1, 2].map(|k| (((a[k] + b[k]) * 0.5 * 1e9).round() / 1e9).floor());
            let ta = [0, 1, 2].map(|k| a[k] - shift[k]);
            let tb = [0, 1, 2].map(|k| b[k] - shift[k]);
            let (ra, rb) = (self.radii[i], self.radii[j]);
            let key = |p: Vec3, r: f64| {
                (
                    p.map(|x| (x * 1e9).round() as i64),
                    (r * 1e12).round() as i64,
                )
            };
            let (ka, kb) = (key(ta, ra), key(tb, rb));
            let ((pa, ra, ka), (pb, rb, kb)) = if ka <= kb {
                ((ta, ra, ka), (tb, rb, kb))
            } else {
                ((tb, rb, kb), (ta, ra, ka))
            };
            if seen.insert((ka, kb)) {
                let ends = [out.node(pa, ra), out.node(pb, rb)];
                out.struts.push(ends);
            }
        }
        out
    }

    /// Reads a cell file: JSON with `nodes` (unit-cell coordinates), `struts` (pairs of node
    /// indices) and, optionally, `radii` (a radius factor per node). Errors name the problem in
    /// one line.
    pub fn from_file(path: &Path) -> Result<UnitCell> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::Io {
            path: path.to_path_buf(),
            source: e,
        })?;
        UnitCell::from_json(&text).map_err(|e| e.in_file(path))
    }

    /// Parses a cell from JSON text (see [`UnitCell::from_file`]).
    pub fn from_json(text: &str) -> Result<UnitCell> {
        #[derive(Deserialize)]
        #[serde(deny_unknown_fields)]
        struct CellFile {
            nodes: Vec<Vec3>,
            struts: Vec<[usize; 2]>,
            radii: Option<Vec<f64>>,
        }
        let f: CellFile = serde_json::from_str(text)
            .map_err(|e| Error::parse(format!("not a strut cell: {e}")))?;
        if f.nodes.is_empty() || f.struts.is_empty() {
            return Err(Error::parse(
                "the cell has no struts: give `nodes` and `struts` (pairs of node indices)",
            ));
        }
        if let Some(i) = f
            .nodes
            .iter()
            .position(|p| p.iter().any(|x| !x.is_finite()))
        {
            return Err(Error::parse(format!(
                "node {i} has a coordinate that is not a number"
            )));
        }
        if let Some((k, s)) = f
            .struts
            .iter()
            .enumerate()
            .find(|(_, s)| s.iter().any(|&i| i >= f.nodes.len()))
        {
            return Err(Error::parse(format!(
                "strut {k} joins node {} to node {}, but the cell has {} nodes (numbered from 0)",
                s[0],
                s[1],
                f.nodes.len()
            )));
        }
        if let Some((k, _)) = f
            .struts
            .iter()
            .enumerate()
            .find(|(_, s)| dist(f.nodes[s[0]], f.nodes[s[1]]) < 1e-9)
        {
            return Err(Error::parse(format!(
                "strut {k} has no length: its ends coincide"
            )));
        }
        let radii = match f.radii {
            None => vec![1.0; f.nodes.len()],
            Some(r) if r.len() != f.nodes.len() => {
                return Err(Error::parse(format!(
                    "`radii` has {} factors for {} nodes",
                    r.len(),
                    f.nodes.len()
                )))
            }
            Some(r) => {
                if let Some(i) = r.iter().position(|&x| !(x > 0.0 && x.is_finite())) {
                    return Err(Error::parse(format!(
                        "radius factor {i} is {}: factors must be positive",
                        r[i]
                    )));
                }
                r
            }
        };
        let cell = UnitCell {
            nodes: f.nodes,
            struts: f.struts,
            radii,
        }
        .canonical();
        match cell.separate_lattices() {
            Some(1) => Ok(cell),
            Some(n) => Err(Error::parse(format!(
                "the struts make {n} separate lattices that pass through each other without a shared node (struts that cross must meet at a node)"
            ))),
            None => Err(Error::parse(
                "the struts do not join into one lattice when the cell is repeated: they form separate layers, chains or pieces (struts that cross must meet at a node)",
            )),
        }
    }

    /// How many separate lattices the struts make when the cell is repeated in every
    /// direction, joined at shared nodes: `Some(1)` for one lattice, `Some(n)` for `n` that
    /// interpenetrate without a shared node, `None` for struts that do not reach across the
    /// cell in all three directions (layers, chains, or isolated pieces: infinitely many).
    ///
    /// Each node stands for its translates; a breadth-first walk over the struts gives each
    /// node the translate it is reached at, and each strut that closes a loop adds the
    /// translation around the loop. The lattice is one when those translations generate every
    /// whole-cell translation: their integer lattice has rank 3 and index 1 (the index is
    /// the number of separate lattices).
    pub fn separate_lattices(&self) -> Option<u64> {
        // Nodes by their place in the cell, and the whole-cell shift of each.
        let mut places: Vec<[i64; 3]> = Vec::new();
        let mut place_of = Vec::with_capacity(self.nodes.len());
        let mut shift_of = Vec::with_capacity(self.nodes.len());
        for p in &self.nodes {
            let key = p.map(|x| ((x * 1e9).round() as i64).rem_euclid(1_000_000_000));
            let shift = [0, 1, 2].map(|k| ((p[k] * 1e9).round() as i64).div_euclid(1_000_000_000));
            let place = places.iter().position(|q| *q == key).unwrap_or_else(|| {
                places.push(key);
                places.len() - 1
            });
            place_of.push(place);
            shift_of.push(shift);
        }
        let used: std::collections::BTreeSet<usize> =
            self.struts.iter().flatten().map(|&i| place_of[i]).collect();
        // Struts between places, with the translation from the first end's copy to the second's.
        let mut adjacent: Vec<Vec<(usize, [i64; 3])>> = vec![Vec::new(); places.len()];
        for &[i, j] in &self.struts {
            let t = [0, 1, 2].map(|k| shift_of[j][k] - shift_of[i][k]);
            adjacent[place_of[i]].push((place_of[j], t));
            adjacent[place_of[j]].push((place_of[i], t.map(|x| -x)));
        }
        let start = *used.iter().next()?;
        let mut at: Vec<Option<[i64; 3]>> = vec![None; places.len()];
        at[start] = Some([0; 3]);
        let mut queue = std::collections::VecDeque::from([start]);
        let mut basis = IntegerLattice::default();
        while let Some(a) = queue.pop_front() {
            let oa = at[a].expect("queued nodes are placed");
            for &(b, t) in &adjacent[a] {
                let reached = [0, 1, 2].map(|k| oa[k] + t[k]);
                match at[b] {
                    None => {
                        at[b] = Some(reached);
                        queue.push_back(b);
                    }
                    Some(ob) => basis.add([0, 1, 2].map(|k| reached[k] - ob[k])),
                }
            }
        }
        if used.iter().any(|&p| at[p].is_none()) {
            return None;
        }
        basis.index()
    }

    /// The cell as a cell file's JSON ([`UnitCell::from_json`] reads it back): `nodes`,
    /// `struts`, and `radii` where a factor is not 1.
    pub fn to_json(&self) -> String {
        let mut v = serde_json::json!({ "nodes": self.nodes, "struts": self.struts });
        if self.radii.iter().any(|&r| r != 1.0) {
            v["radii"] = serde_json::json!(self.radii);
        }
        let mut s = serde_json::to_string(&v).expect("a cell is plain JSON");
        s.push('\n');
        s
    }

    /// The cell as struts of a lattice with cells of `size` mm: each strut's ends in mm,
    /// relative to its cell's lower corner, and their radius factors.
    pub fn segments(&self, size: Vec3) -> Vec<([Vec3; 2], [f64; 2])> {
        self.struts
            .iter()
            .map(|&[i, j]| {
                let p = |n: usize| [0, 1, 2].map(|k| self.nodes[n][k] * size[k]);
                ([p(i), p(j)], [self.radii[i], self.radii[j]])
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn built_in_cells_have_their_strut_counts_per_period() {
        // Struts per cubic period, each once: sc 3 (one per axis), bcc 8 half-diagonals,
        // fcc 12 half face diagonals (opposite faces are translates), octet 12 + 12, Kelvin 24
        // (2 truncated octahedra per cell × 36 edges ÷ 3 cells per edge), diamond 16 bonds,
        // rhombic 32 (4 rhombic dodecahedra × 24 edges ÷ 3).
        for (name, n) in [
            ("sc", 3),
            ("bcc", 8),
            ("bccz", 9),
            ("fcc", 12),
            ("fccz", 13),
            ("octet", 24),
            ("kelvin", 24),
            ("diamond", 16),
            ("rhombic", 32),
        ] {
            let c = UnitCell::built_in(name).unwrap();
            assert_eq!(c.struts.len(), n, "{name}");
        }
    }

    #[test]
    fn built_in_cells_are_one_lattice_and_broken_cells_are_not() {
        for name in BUILT_IN {
            let c = UnitCell::built_in(name).unwrap();
            assert_eq!(c.separate_lattices(), Some(1), "{name}");
        }
        let cell = |nodes: &[Vec3], struts: &[[usize; 2]]| {
            UnitCell {
                nodes: nodes.to_vec(),
                struts: struts.to_vec(),
                radii: vec![1.0; nodes.len()],
            }
            .canonical()
        };
        // Chains along x only; layers in the plane x = 0 ... spanned by (1,0,0) and (0,1,1).
        let chain = cell(&[[0.0; 3], [1.0, 0.0, 0.0]], &[[0, 1]]);
        assert_eq!(chain.separate_lattices(), None);
        let layers = cell(
            &[[0.5; 3], [1.5, 0.5, 0.5], [0.5, 1.5, 1.5], [1.5, 1.5, 1.5]],
            &[[0, 1], [0, 2], [0, 3]],
        );
        assert_eq!(layers.separate_lattices(), None);
        // Struts joining each point to its translates by (2,0,0)-style steps: the body-centred
        // sub-lattice {(a, b, c): a + b + c even} of sc, two lattices.
        let two = cell(
            &[[0.0; 3], [1.0, 1.0, 0.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]],
            &[[0, 1], [0, 2], [0, 3]],
        );
        assert_eq!(two.separate_lattices(), Some(2));
        // A node not joined to the rest: isolated pieces.
        let island = cell(
            &[
                [0.0; 3],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
                [0.3; 3],
                [0.6; 3],
            ],
            &[[0, 1], [0, 2], [0, 3], [4, 5]],
        );
        assert_eq!(island.separate_lattices(), None);
        assert!(UnitCell::from_json(
            r#"{"nodes": [[0,0,0],[1,1,0],[1,0,1],[0,1,1]], "struts": [[0,1],[0,2],[0,3]]}"#
        )
        .unwrap_err()
        .to_string()
        .contains("2 separate lattices"));
    }

    #[test]
    fn every_node_of_a_built_in_cell_has_its_coordination() {
        // Struts meeting at each node of the infinite lattice: counted over the 27 translates.
        for (name, degrees) in [
            ("sc", vec![6]),
            ("bcc", vec![8]),
            ("kelvin", vec![4]),
            ("diamond", vec![4]),
            ("rhombic", vec![4, 8]),
            ("fcc", vec![4, 12]),
            ("octet", vec![12]),
        ] {
            let c = UnitCell::built_in(name).unwrap();
            let segs = c.segments([1.0; 3]);
            for (s, _) in &segs {
                for end in s {
                    let mut degree = 0;
                    for (t, _) in &segs {
                        for sh in 0..27 {
                            let d = [sh % 3, (sh / 3) % 3, sh / 9].map(|x| x as f64 - 1.0);
                            for q in t {
                                let q = [0, 1, 2].map(|k| q[k] + d[k]);
                                degree += (dist(q, *end) < 1e-9) as usize;
                            }
                        }
                    }
                    assert!(
                        degrees.contains(&degree),
                        "{name}: a node of degree {degree} at {end:?}"
                    );
                }
            }
        }
    }

    /// A cell written as JSON reads back as the same cell, radius factors included.
    #[test]
    fn a_cell_written_as_json_reads_back_the_same() {
        for name in BUILT_IN {
            let c = UnitCell::built_in(name).unwrap();
            assert_eq!(UnitCell::from_json(&c.to_json()).unwrap(), c, "{name}");
        }
        let mut c = UnitCell::built_in("bcc").unwrap();
        c.radii[0] = 1.5;
        let back = UnitCell::from_json(&c.to_json()).unwrap();
        assert_eq!(back, c.canonical());
        assert!(c.to_json().contains("radii"));
    }

    #[test]
    fn a_cell_file_is_read_and_bad_ones_are_refused_with_the_reason() {
        let c = UnitCell::from_json(
            r#"{"nodes": [[0.5,0.5,0.5],[0,0,0],[1,0,0],[0,1,0],[1,1,0],[0,0,1],[1,0,1],[0,1,1],[1,1,1]],
                "struts": [[0,1],[0,2],[0,3],[0,4],[0,5],[0,6],[0,7],[0,8]]}"#,
        )
        .unwrap();
        assert_eq!(c, UnitCell::built_in("bcc").unwrap());
        for (text, says) in [
            ("{", "not a strut cell"),
            (r#"{"nodes": [], "struts": []}"#, "no struts"),
            (
                r#"{"nodes": [[0,0,0]], "struts": [[0,1]]}"#,
                "strut 0 joins node 0 to node 1",
            ),
            (
                r#"{"nodes": [[0,0,0],[0,0,0]], "struts": [[0,1]]}"#,
                "no length",
            ),
            (
                r#"{"nodes": [[0,0,0],[1,0,0]], "struts": [[0,1]], "radii": [1]}"#,
                "1 factors for 2 nodes",
            ),
            (
                r#"{"nodes": [[0,0,0],[1,0,0]], "struts": [[0,1]], "radii": [1, -2]}"#,
                "factors must be positive",
            ),
            (
                r#"{"nodes": [[0,0,0]], "struts": [[0,0]], "edges": 1}"#,
                "unknown field",
            ),
        ] {
            let e = UnitCell::from_json(text).unwrap_err().to_string();
            assert!(e.contains(says), "{text}: {e}");
            assert!(!e.contains('\n'), "{e}");
        }
    }
}
