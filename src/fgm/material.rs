//! Material: features the composition is graded from, the distance to them, and the laws that
//! turn that distance into material fractions.
//!
//! The distance `d` at a point is the distance to the nearest feature (or a weighted mean of
//! the distances to each): a point, a polyline, a surface (a mesh), or the part's own skin. Each
//! material but the last has a law `fₖ(d)`; the last takes the rest, `1 − Σ fₖ`, so that the
//! fractions sum to 1 everywhere and — because they depend on `d` alone — every iso-surface of
//! the distance has one composition. Laws: a power of `d / d_max` (`p = 1`: linear), a smooth
//! step between two distances, or a piecewise-linear table of (distance, fraction).

use crate::error::{Error, Result};
use crate::field::Vec3;
use crate::geom::bvh::Bvh;
use std::path::Path;

/// What the composition is graded from.
pub enum Feature {
    /// A point, mm.
    Point(Vec3),
    /// A polyline through these points (at least two).
    Curve(Vec<Vec3>),
    /// A surface: a mesh's triangles.
    Surface(Box<Bvh>),
    /// The part's own surface.
    Skin,
}

impl Feature {
    /// Parses `point:X,Y,Z`, `curve:FILE` (a text point list, one vertex a line),
    /// `surface:FILE` (a mesh: .stl, .obj, .off, .ply, .3mf) or `skin`; in the plane
    /// (`planar`), `point:X,Y`, a curve of `x y` lines, and no surface.
    pub fn parse(s: &str, planar: bool) -> Result<Feature> {
        let (kind, arg) = s.split_once(':').unwrap_or((s, ""));
        match kind.trim() {
            "skin" if arg.is_empty() => Ok(Feature::Skin),
            "point" if planar => {
                let v: Vec<f64> = arg
                    .split(',')
                    .map(|x| x.trim().parse::<f64>())
                    .collect::<std::result::Result<_, _>>()
                    .unwrap_or_default();
                if v.len() != 2 || !v.iter().all(|x| x.is_finite()) {
                    return Err(Error::invalid(format!(
                        "feature '{s}': point:X,Y needs two finite numbers in the plane"
                    )));
                }
                Ok(Feature::Point([v[0], v[1], 0.0]))
            }
            "surface" if planar => Err(Error::invalid(format!(
                "feature '{s}': a plane contour is graded from point:X,Y, curve:FILE or skin"
            ))),
            "point" => {
                let v: Vec<f64> = arg
                    .split(',')
                    .map(|x| x.trim().parse::<f64>())
                    .collect::<std::result::Result<_, _>>()
                    .map_err(|_| {
                        Error::invalid(format!("feature '{s}': point:X,Y,Z needs three numbers"))
                    })?;
                if v.len() != 3 || !v.iter().all(|x| x.is_finite()) {
                    return Err(Error::invalid(format!(
                        "feature '{s}': point:X,Y,Z needs three finite numbers"
                    )));
                }
                Ok(Feature::Point([v[0], v[1], v[2]]))
            }
            "curve" => {
                let path = Path::new(arg);
                let pts = match planar {
                    true => crate::io::points::read_plane(path)?.points,
                    false => crate::io::points::read(path)?.points,
                };
                if pts.len() < 2 {
                    return Err(Error::invalid(format!(
                        "{}: a curve needs at least two points",
                        path.display()
                    )));
                }
                Ok(Feature::Curve(pts))
            }
            "surface" => {
                let path = Path::new(arg);
                let mesh = crate::mesh::part::read(path, &crate::io::ReadOptions::default())?.mesh;
                if mesh.triangle_count() == 0 {
                    return Err(Error::invalid(format!("{}: no triangles", path.display())));
                }
                Ok(Feature::Surface(Box::new(Bvh::new(&mesh))))
            }
            k => Err(Error::invalid(format!(
                "unknown feature '{k}' (known: point:X,Y,Z, curve:FILE.csv, surface:FILE.stl, skin)"
            ))),
        }
    }

    /// The distance from `p` to the feature; `skin` is the distance to the part's surface.
    pub fn distance(&self, p: Vec3, skin: f64) -> f64 {
        match self {
            Feature::Point(c) => norm(sub(p, *c)),
            Feature::Curve(pts) => pts
                .windows(2)
                .map(|s| segment_distance(p, s[0], s[1]))
                .fold(f64::INFINITY, f64::min),
            Feature::Surface(bvh) => bvh.distance(p, f64::INFINITY),
            Feature::Skin => skin,
        }
    }

    /// The feature's name in reports.
    pub fn name(&self) -> &'static str {
        match self {
            Feature::Point(_) => "point",
            Feature::Curve(_) => "curve",
            Feature::Surface(_) => "surface",
            Feature::Skin => "skin",
        }
    }
}

/// The features and how their distances combine.
pub struct Features {
    /// The features.
    pub list: Vec<Feature>,
    /// One weight per feature: the distance is the weighted mean; `None`: the nearest.
    pub weights: Option<Vec<f64>>,
}

impl Features {
    /// Whether a feature is the part's skin (its distance must then be computed).
    pub fn uses_skin(&self) -> bool {
        self.list.iter().any(|f| matches!(f, Feature::Skin))
    }

    /// The combined distance at `p`.
    pub fn distance(&self, p: Vec3, skin: f64) -> f64 {
        match &self.weights {
            None => self
                .list
                .iter()
                .map(|f| f.distance(p, skin))
                .fold(f64::INFINITY, f64::min),
            Some(w) => {
                let total: f64 = w.iter().sum();
                self.list
                    .iter()
                    .zip(w)
                    .map(|(f, w)| w * f.distance(p, skin))
                    .sum::<f64>()
                    / total
            }
        }
    }
}

/// How one material's fraction follows the distance.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(tag = "law", rename_all = "lowercase")]
pub enum Law {
    /// `(d / d_max)^p`.
    Power {
        /// The exponent.
        p: f64,
    },
    /// 0 up to `from` mm, 1 from `to` mm, a smooth step (3t² − 2t³) between.
    Step {
        /// Where the step starts, mm.
        from: f64,
        /// Where it ends, mm.
        to: f64,
    },
    /// Piecewise linear through (distance mm, fraction) pairs, constant beyond the ends.
    Table {
        /// The pairs, by increasing distance.
        points: Vec<(f64, f64)>,
    },
}

impl Law {
    /// Parses `linear`, `power:P`, `step:FROM:TO` or `table:FILE.csv` (rows of distance,
    /// fraction).
    pub fn parse(s: &str) -> Result<Law> {
        let bad = |why: &str| Error::invalid(format!("law '{s}': {why}"));
        let num = |x: &str| {
            x.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| bad(&format!("'{x}' is not a number")))
        };
        let mut parts = s.splitn(2, ':');
        let kind = parts.next().unwrap_or("").trim();
        let arg = parts.next().unwrap_or("");
        match kind {
            "linear" => Ok(Law::Power { p: 1.0 }),
            "power" => {
                let p = num(arg)?;
                if p <= 0.0 {
                    return Err(bad("the exponent must be positive"));
                }
                Ok(Law::Power { p })
            }
            "step" => {
                let (a, b) = arg
                    .split_once(':')
                    .ok_or_else(|| bad("step:FROM:TO needs two distances"))?;
                let (from, to) = (num(a)?, num(b)?);
                if !(to > from && from >= 0.0) {
                    return Err(bad("step:FROM:TO needs 0 ≤ FROM < TO"));
                }
                Ok(Law::Step { from, to })
            }
            "table" => {
                let path = Path::new(arg);
                let rows = crate::io::points::read_columns(path, 2)?;
                if rows.len() < 2 {
                    return Err(Error::invalid(format!(
                        "{}: a law table needs at least two rows of distance, fraction",
                        path.display()
                    )));
                }
                if rows.windows(2).any(|w| w[1][0] <= w[0][0]) {
                    return Err(Error::invalid(format!(
                        "{}: the distances of a law table must increase row by row",
                        path.display()
                    )));
                }
                Ok(Law::Table {
                    points: rows.iter().map(|r| (r[0], r[1])).collect(),
                })
            }
            _ => Err(bad(
                "known laws: linear, power:P, step:FROM:TO, table:FILE.csv",
            )),
        }
    }

    /// The fraction at distance `d` (mm) in a part whose largest distance is `dmax`.
    pub fn at(&self, d: f64, dmax: f64) -> f64 {
        match self {
            Law::Power { p } => (d / dmax).clamp(0.0, 1.0).powf(*p),
            Law::Step { from, to } => {
                let t = ((d - from) / (to - from)).clamp(0.0, 1.0);
                t * t * (3.0 - 2.0 * t)
            }
            Law::Table { points } => {
                let (first, last) = (points[0], points[points.len() - 1]);
                if d <= first.0 {
                    return first.1;
                }
                if d >= last.0 {
                    return last.1;
                }
                let k = points.partition_point(|q| q.0 <= d);
                let (a, b) = (points[k - 1], points[k]);
                a.1 + (b.1 - a.1) * (d - a.0) / (b.0 - a.0)
            }
        }
    }

    /// Distances where the law bends (a table's rows, a step's ends), for checks to visit.
    fn knots(&self) -> Vec<f64> {
        match self {
            Law::Power { .. } => Vec::new(),
            Law::Step { from, to } => vec![*from, *to],
            Law::Table { points } => points.iter().map(|p| p.0).collect(),
        }
    }
}

/// Named materials and their laws: one per material but the last, which takes the rest (or
/// one for every material, when they sum to 1 by themselves).
#[derive(Debug, Clone, serde::Serialize)]
pub struct Composition {
    /// The materials' names.
    pub materials: Vec<String>,
    /// The laws, in the materials' order.
    pub laws: Vec<Law>,
}

impl Composition {
    /// Checks the names and the number of laws.
    pub fn new(materials: Vec<String>, laws: Vec<Law>) -> Result<Composition> {
        if materials.len() < 2 {
            return Err(Error::invalid(
                "name at least two materials (--materials A,B)",
            ));
        }
        for (i, m) in materials.iter().enumerate() {
            let ok = !m.is_empty()
                && m.chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
            if !ok {
                return Err(Error::invalid(format!(
                    "material name '{m}': use letters, digits, '_' and '-' (it names a grid)"
                )));
            }
            if materials[..i].contains(m) || m == "sdf" || m == "distance" {
                return Err(Error::invalid(format!("material name '{m}' is used twice")));
            }
        }
        let n = materials.len();
        if laws.len() + 1 != n && laws.len() != n {
            return Err(Error::invalid(format!(
                "{n} materials need {} laws (one per material, the last taking the rest) or {n}; {} given",
                n - 1,
                laws.len()
            )));
        }
        Ok(Composition { materials, laws })
    }

    /// The fractions at distance `d`, into `out` (one per material).
    pub fn fractions(&self, d: f64, dmax: f64, out: &mut [f64]) {
        let mut rest = 1.0;
        for (o, law) in out.iter_mut().zip(&self.laws) {
            *o = law.at(d, dmax);
            rest -= *o;
        }
        if self.laws.len() < self.materials.len() {
            out[self.materials.len() - 1] = rest;
        }
    }

    /// Refuses laws that leave a fraction outside [0, 1] or do not sum to 1 at some distance
    /// in `[0, dmax]` (visited finely and at every knot).
    pub fn check(&self, dmax: f64) -> Result<()> {
        let mut ds: Vec<f64> = (0..=1000).map(|i| dmax * i as f64 / 1000.0).collect();
        ds.extend(
            self.laws
                .iter()
                .flat_map(|l| l.knots())
                .filter(|d| *d <= dmax),
        );
        let mut f = vec![0.0; self.materials.len()];
        for d in ds {
            self.fractions(d, dmax, &mut f);
            let sum: f64 = f.iter().sum();
            if let Some(k) = f.iter().position(|x| !(-1e-9..=1.0 + 1e-9).contains(x)) {
                return Err(Error::invalid(format!(
                    "the laws give {} a fraction of {:.4} at distance {:.4} mm; fractions must lie in [0, 1] and sum to 1",
                    self.materials[k], f[k], d
                )));
            }
            if (sum - 1.0).abs() > 1e-6 {
                return Err(Error::invalid(format!(
                    "the laws sum to {sum:.4} at distance {d:.4} mm, not 1: give one law fewer than materials so the last takes the rest"
                )));
            }
        }
        Ok(())
    }
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm(a: Vec3) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// The distance from `p` to the segment `ab`.
fn segment_distance(p: Vec3, a: Vec3, b: Vec3) -> f64 {
    let ab = sub(b, a);
    let l2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
    let ap = sub(p, a);
    let t = if l2 > 0.0 {
        ((ap[0] * ab[0] + ap[1] * ab[1] + ap[2] * ab[2]) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    norm(sub(ap, ab.map(|x| x * t)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn laws_and_their_checks() {
        let two = Composition::new(
            vec!["A".into(), "B".into()],
            vec![Law::parse("linear").unwrap()],
        )
        .unwrap();
        let mut f = [0.0; 2];
        two.fractions(2.5, 10.0, &mut f);
        assert_eq!(f, [0.25, 0.75]);
        two.check(10.0).unwrap();
        let three = Composition::new(
            vec!["A".into(), "B".into(), "C".into()],
            vec![
                Law::parse("power:2").unwrap(),
                Law::parse("step:1:5").unwrap(),
            ],
        )
        .unwrap();
        let e = three.check(10.0).unwrap_err().to_string();
        assert!(e.contains("C") && e.contains("fraction"), "{e}");
        let both = Composition::new(
            vec!["A".into(), "B".into()],
            vec![Law::parse("linear").unwrap(), Law::parse("linear").unwrap()],
        )
        .unwrap();
        assert!(both.check(1.0).unwrap_err().to_string().contains("sum to"));
        assert!(Law::parse("cubic").is_err());
        assert!(Law::parse("step:5:1").is_err());
        assert_eq!(
            segment_distance([1.0, 1.0, 0.0], [0.0; 3], [2.0, 0.0, 0.0]),
            1.0
        );
        assert!(
            matches!(Feature::parse("line:1,2,3", false), Err(e) if e.to_string().contains("unknown feature"))
        );
    }
}
