//! Density fields: the volume fraction a graded part should have at each point — a linear grade
//! along an axis, an expression in `x, y, z` (and `d`, the distance to a filled part's skin), or
//! a sampled `.npy` array spanning the part's box or a grid of a `.vdb` in the part's own
//! coordinates, read trilinearly.
//!
//! Expressions are compiled and evaluated by the `exmex` crate; they are read first by a small
//! recursive-descent reader here, which points at the column of a syntax error, refuses names
//! that are not variables, constants or functions, and hands `exmex` the expression fully
//! parenthesised (so `-x^2` is `-(x²)`, as in mathematics, and `2^3^2` is `2^(3^2)`).

use super::nodes::Nodes;
use super::{Aabb, Vec3};
use crate::error::{Error, Result};
use exmex::Express;
use std::path::Path;

/// One-argument functions an expression may call.
const FUNCTIONS: [&str; 18] = [
    "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "sqrt", "exp", "ln",
    "log10", "log2", "abs", "floor", "ceil", "signum",
];
/// Two-argument functions.
const FUNCTIONS2: [&str; 3] = ["min", "max", "atan2"];
/// Constants.
const CONSTANTS: [&str; 2] = ["PI", "E"];
/// Variables, in the order they are handed to the evaluator.
const VARIABLES: [&str; 4] = ["d", "x", "y", "z"];

/// A density field over a part's box.
pub struct DensityField {
    kind: Kind,
    /// How the field was given, for reports.
    pub source: String,
}

enum Kind {
    /// Linear along `axis` from `a` at the box's lower face to `b` at its upper face.
    Grade {
        axis: usize,
        a: f64,
        b: f64,
        lo: f64,
        hi: f64,
    },
    /// An expression; `vars[i]` is the index into [`VARIABLES`] of the evaluator's `i`-th
    /// variable.
    Expr {
        expr: Box<exmex::FlatEx<f64>>,
        vars: Vec<usize>,
    },
    /// Samples at the nodes of a regular grid whose corners are the box's corners.
    Samples(Nodes),
    /// Another field's values carried through an increasing table of `(value, density)`.
    Through {
        inner: Box<DensityField>,
        table: Vec<(f64, f64)>,
        hold: bool,
    },
}

impl DensityField {
    /// `AXIS:A:B`: linear along x, y or z across `bounds` from `A` to `B`.
    pub fn grade(spec: &str, bounds: &Aabb) -> Result<DensityField> {
        let bad = || Error::invalid(format!("a grade is AXIS:A:B (as z:0.1:0.4), got '{spec}'"));
        let parts: Vec<&str> = spec.split(':').collect();
        let [axis, a, b] = parts[..] else {
            return Err(bad());
        };
        let axis = match axis.trim().to_ascii_lowercase().as_str() {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return Err(bad()),
        };
        let num = |s: &str| s.trim().parse::<f64>().ok().filter(|v| v.is_finite());
        let (a, b) = (num(a).ok_or_else(bad)?, num(b).ok_or_else(bad)?);
        Ok(DensityField {
            kind: Kind::Grade {
                axis,
                a,
                b,
                lo: bounds.min[axis],
                hi: bounds.max[axis],
            },
            source: format!("grade {spec}"),
        })
    }

    /// An expression, or a `.npy` file of samples spanning `bounds`.
    pub fn parse(spec: &str, bounds: &Aabb) -> Result<DensityField> {
        Self::parse_named(spec, bounds, "density")
    }

    /// As [`DensityField::parse`], for a field named `noun` in messages (a density, a cell
    /// size).
    pub fn parse_named(spec: &str, bounds: &Aabb, noun: &str) -> Result<DensityField> {
        if spec.to_ascii_lowercase().ends_with(".npy") {
            return Self::samples(Path::new(spec), bounds, noun);
        }
        let text = normalise(Source { text: spec, noun })?;
        let expr = exmex::parse::<f64>(&text)
            .map_err(|e| Error::invalid(format!("{noun} expression '{spec}': {e}")))?;
        let vars = expr
            .var_names()
            .iter()
            .map(|v| {
                VARIABLES
                    .iter()
                    .position(|n| n == v)
                    .expect("names checked")
            })
            .collect();
        Ok(DensityField {
            kind: Kind::Expr {
                expr: Box::new(expr),
                vars,
            },
            source: format!("expression {spec}"),
        })
    }

    /// A `.npy` array of shape `(nx, ny, nz)`, each axis at least 2, its first and last samples
    /// on the box's faces.
    fn samples(path: &Path, bounds: &Aabb, noun: &str) -> Result<DensityField> {
        let bytes = std::fs::read(path)
            .map_err(|e| Error::invalid(format!("cannot read {}: {e}", path.display())))?;
        let a = crate::io::npy::parse(&bytes)
            .map_err(|e| Error::invalid(format!("{}: {e}", path.display())))?;
        if a.shape.len() != 3 || a.shape.iter().any(|&n| n < 2) {
            return Err(Error::invalid(format!(
                "{}: a {noun} field is a 3-D array of at least 2 samples per axis spanning the box, got shape {:?}",
                path.display(),
                a.shape
            )));
        }
        let n = [a.shape[0], a.shape[1], a.shape[2]];
        let size = bounds.size();
        Ok(DensityField {
            kind: Kind::Samples(Nodes {
                origin: bounds.min,
                step: [0, 1, 2].map(|i| size[i] / (n[i] - 1) as f64),
                n,
                values: a.data,
            }),
            source: format!("samples {}", path.display()),
        })
    }

    /// The same density everywhere.
    pub fn constant(density: f64) -> DensityField {
        DensityField {
            kind: Kind::Grade {
                axis: 0,
                a: density,
                b: density,
                lo: 0.0,
                hi: 1.0,
            },
            source: format!("constant {density}"),
        }
    }

    /// Values at nodes placed in the part's coordinates (a grid read from a `.vdb`), read
    /// trilinearly and held at the outer nodes beyond them.
    pub fn nodes(nodes: Nodes, source: String) -> DensityField {
        DensityField {
            kind: Kind::Samples(nodes),
            source,
        }
    }

    /// `inner`'s values carried through `table`, pairs `(value, density)` increasing in both
    /// (as a lattice's relative stiffness against its density): piecewise linear in the
    /// logarithms; beyond the table, its end densities where `hold`, else the end pieces' power
    /// laws (below 0.999); values that are not positive give no density (NaN).
    pub fn through(
        inner: DensityField,
        table: Vec<(f64, f64)>,
        hold: bool,
        source: String,
    ) -> Result<DensityField> {
        let increasing = table.windows(2).all(|w| w[1].0 > w[0].0 && w[1].1 > w[0].1);
        if table.len() < 2 || !increasing || table.iter().any(|&(x, y)| !(x > 0.0 && y > 0.0)) {
            return Err(Error::invalid(
                "a table from a field to densities needs two or more points, positive and increasing",
            ));
        }
        Ok(DensityField {
            kind: Kind::Through {
                inner: Box::new(inner),
                table,
                hold,
            },
            source,
        })
    }

    /// Whether the field reads the distance to a part's skin (`d`).
    pub fn uses_distance(&self) -> bool {
        match &self.kind {
            Kind::Expr { vars, .. } => vars.contains(&0),
            Kind::Through { inner, .. } => inner.uses_distance(),
            _ => false,
        }
    }

    /// The field at `p`, `d` mm inside the part's skin.
    pub fn at(&self, p: Vec3, d: f64) -> f64 {
        match &self.kind {
            Kind::Grade { axis, a, b, lo, hi } => {
                let s = ((p[*axis] - lo) / (hi - lo)).clamp(0.0, 1.0);
                a + (b - a) * s
            }
            Kind::Expr { expr, vars } => {
                let all = [d, p[0], p[1], p[2]];
                let args: Vec<f64> = vars.iter().map(|&i| all[i]).collect();
                expr.eval(&args).unwrap_or(f64::NAN)
            }
            Kind::Samples(nodes) => nodes.at(p),
            Kind::Through { inner, table, hold } => {
                let v = inner.at(p, d);
                if v.is_nan() || v <= 0.0 {
                    return f64::NAN;
                }
                let (first, last) = (table[0], table[table.len() - 1]);
                if *hold && v <= first.0 {
                    return first.1;
                }
                if *hold && v >= last.0 {
                    return last.1;
                }
                // The piece holding v (the first or last beyond the table's ends).
                let k = table
                    .partition_point(|&(x, _)| x <= v)
                    .clamp(1, table.len() - 1);
                let ((x0, y0), (x1, y1)) = (table[k - 1], table[k]);
                let t = (v.ln() - x0.ln()) / (x1.ln() - x0.ln());
                // A density, below the solid's whatever the law beyond the table says.
                (y0.ln() + t * (y1.ln() - y0.ln())).exp().min(0.999)
            }
        }
    }
}

/// A token of an expression, with its 1-based column.
#[derive(Debug, Clone, PartialEq)]
enum Token {
    Number(String),
    Name(String),
    Op(char),
}

/// An expression's text and what it gives (for messages).
#[derive(Clone, Copy)]
struct Source<'a> {
    text: &'a str,
    noun: &'a str,
}

fn tokens(s: Source) -> Result<Vec<(Token, usize)>> {
    let chars: Vec<char> = s.text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let col = i + 1;
        if c.is_whitespace() {
            i += 1;
        } else if c.is_ascii_digit() || c == '.' {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
                i += 1;
            }
            // An exponent: 1e-3, 2.5E+2.
            if i < chars.len() && (chars[i] == 'e' || chars[i] == 'E') {
                let mut j = i + 1;
                if j < chars.len() && (chars[j] == '+' || chars[j] == '-') {
                    j += 1;
                }
                if j < chars.len() && chars[j].is_ascii_digit() {
                    i = j;
                    while i < chars.len() && chars[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let text: String = chars[start..i].iter().collect();
            if text.parse::<f64>().is_err() {
                return Err(syntax(s, col, &format!("'{text}' is not a number")));
            }
            out.push((Token::Number(text), col));
        } else if c.is_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            out.push((Token::Name(chars[start..i].iter().collect()), col));
        } else if "+-*/^(),".contains(c) {
            out.push((Token::Op(c), col));
            i += 1;
        } else {
            return Err(syntax(s, col, &format!("unexpected '{c}'")));
        }
    }
    Ok(out)
}

fn syntax(s: Source, col: usize, what: &str) -> Error {
    Error::invalid(format!(
        "{} expression '{}', column {col}: {what} (names: x, y, z in mm, d the distance to the skin when filling; PI, E; functions: {}, {})",
        s.noun,
        s.text,
        FUNCTIONS.join(", "),
        FUNCTIONS2.join(", ")
    ))
}

/// Reads `s`, refusing it with the column of the first error, and returns it fully
/// parenthesised for the evaluator.
fn normalise(s: Source) -> Result<String> {
    let toks = tokens(s)?;
    let mut r = Reader {
        s,
        toks: &toks,
        at: 0,
    };
    if toks.is_empty() {
        return Err(syntax(s, 1, "the expression is empty"));
    }
    let e = r.expr()?;
    if let Some((t, col)) = toks.get(r.at) {
        return Err(match t {
            Token::Op(')') => syntax(s, *col, "')' closes nothing"),
            _ => syntax(s, *col, "expected an operator (+ - * / ^) here"),
        });
    }
    Ok(e)
}

struct Reader<'a> {
    s: Source<'a>,
    toks: &'a [(Token, usize)],
    at: usize,
}

impl Reader<'_> {
    fn peek(&self) -> Option<&Token> {
        self.toks.get(self.at).map(|t| &t.0)
    }

    fn column(&self) -> usize {
        self.toks
            .get(self.at)
            .map_or(self.s.text.chars().count() + 1, |t| t.1)
    }

    fn eat(&mut self, c: char) -> bool {
        if self.peek() == Some(&Token::Op(c)) {
            self.at += 1;
            true
        } else {
            false
        }
    }

    /// Left-associative operators `ops` between operands read by `operand`.
    fn chain(
        &mut self,
        ops: [char; 2],
        operand: fn(&mut Self) -> Result<String>,
    ) -> Result<String> {
        let mut e = operand(self)?;
        while let Some(Token::Op(op)) = self.peek().cloned() {
            if !ops.contains(&op) {
                break;
            }
            self.at += 1;
            e = format!("({e}{op}{})", operand(self)?);
        }
        Ok(e)
    }

    fn expr(&mut self) -> Result<String> {
        self.chain(['+', '-'], Self::term)
    }

    fn term(&mut self) -> Result<String> {
        self.chain(['*', '/'], Self::unary)
    }

    fn unary(&mut self) -> Result<String> {
        if self.eat('-') {
            return Ok(format!("(-{})", self.unary()?));
        }
        if self.eat('+') {
            return self.unary();
        }
        let base = self.primary()?;
        if self.eat('^') {
            return Ok(format!("({base}^{})", self.unary()?));
        }
        Ok(base)
    }

    fn primary(&mut self) -> Result<String> {
        let col = self.column();
        let Some((tok, _)) = self.toks.get(self.at).cloned() else {
            return Err(syntax(
                self.s,
                col,
                "the expression ends where a number, a name or '(' was expected",
            ));
        };
        self.at += 1;
        match tok {
            // Written out without an exponent, which the evaluator does not read.
            Token::Number(n) => Ok(format!("({})", n.parse::<f64>().expect("lexed"))),
            Token::Op('(') => {
                let e = self.expr()?;
                if !self.eat(')') {
                    return Err(syntax(
                        self.s,
                        self.column(),
                        &format!("expected ')' to close the '(' of column {col}"),
                    ));
                }
                Ok(e)
            }
            Token::Name(name) => {
                let arity = if FUNCTIONS.contains(&name.as_str()) {
                    1
                } else if FUNCTIONS2.contains(&name.as_str()) {
                    2
                } else if VARIABLES.contains(&name.as_str()) || CONSTANTS.contains(&name.as_str()) {
                    return Ok(name);
                } else {
                    return Err(syntax(self.s, col, &format!("unknown name '{name}'")));
                };
                if !self.eat('(') {
                    return Err(syntax(
                        self.s,
                        self.column(),
                        &format!("expected '(' after the function {name}"),
                    ));
                }
                let mut args = vec![self.expr()?];
                while self.eat(',') {
                    args.push(self.expr()?);
                }
                if !self.eat(')') {
                    return Err(syntax(
                        self.s,
                        self.column(),
                        &format!("expected ')' to close {name}("),
                    ));
                }
                if args.len() != arity {
                    return Err(syntax(
                        self.s,
                        col,
                        &format!("{name} takes {arity} argument(s), got {}", args.len()),
                    ));
                }
                Ok(format!("{name}({})", args.join(",")))
            }
            Token::Op(c) => Err(syntax(
                self.s,
                col,
                &format!("expected a number, a name or '(' before '{c}'"),
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit() -> Aabb {
        Aabb {
            min: [0.0; 3],
            max: [10.0, 20.0, 30.0],
        }
    }

    fn eval(s: &str, p: Vec3) -> f64 {
        DensityField::parse(s, &unit()).unwrap().at(p, 0.0)
    }

    /// Through a table of a power law, values come back on the law, inside the table and beyond
    /// it; values that are not positive give no density.
    #[test]
    fn a_table_carries_values_along_its_law() {
        let law = |x: f64| 0.9 * x.powf(0.5);
        let table: Vec<(f64, f64)> = [0.01, 0.04, 0.1, 0.3]
            .iter()
            .map(|&x| (x, law(x)))
            .collect();
        for x in [0.005, 0.02, 0.2, 0.3, 0.5] {
            let f =
                DensityField::through(DensityField::constant(x), table.clone(), false, "t".into())
                    .unwrap();
            assert!((f.at([0.0; 3], 0.0) - law(x)).abs() < 1e-12, "{x}");
        }
        let held =
            DensityField::through(DensityField::constant(0.5), table.clone(), true, "t".into())
                .unwrap();
        assert_eq!(held.at([0.0; 3], 0.0), law(0.3));
        let f = DensityField::through(
            DensityField::constant(-0.1),
            table.clone(),
            false,
            "t".into(),
        )
        .unwrap();
        assert!(f.at([0.0; 3], 0.0).is_nan());
        let falling = vec![(0.1, 0.3), (0.2, 0.2)];
        assert!(
            DensityField::through(DensityField::constant(0.1), falling, false, "t".into()).is_err()
        );
    }

    #[test]
    fn expressions_follow_mathematical_precedence() {
        let p = [3.0, 2.0, 1.0];
        assert_eq!(eval("-x^2", p), -9.0);
        assert_eq!(eval("2^3^2", p), 512.0);
        assert_eq!(eval("1 - 2 - 3", p), -4.0);
        assert_eq!(eval("8 / 4 / 2", p), 1.0);
        assert_eq!(eval("2*-x", p), -6.0);
        assert!((eval("0.1 + 0.3*z/30 + min(x, y)*1e-3", p) - (0.11 + 0.002)).abs() < 1e-12);
        assert!((eval("sin(PI*x/6)", p) - 1.0).abs() < 1e-12);
        assert!((eval("atan2(y, x)", p) - 2f64.atan2(3.0)).abs() < 1e-12);
    }

    #[test]
    fn syntax_errors_name_the_column() {
        for (s, col) in [
            ("0.1 + * z", 7),
            ("0.1 + q", 7),
            ("sin(x", 6),
            ("0.2 + 0.1*x)", 12),
            ("min(x)", 1),
            ("0.1 $ 2", 5),
            ("0.3 0.2", 5),
            ("", 1),
        ] {
            let e = DensityField::parse(s, &unit()).err().expect(s).to_string();
            assert!(e.contains(&format!("column {col}:")), "{s}: {e}");
            assert!(!e.contains('\n'));
        }
    }

    #[test]
    fn grades_and_samples_interpolate() {
        let g = DensityField::grade("z:0.1:0.4", &unit()).unwrap();
        assert!((g.at([0.0, 0.0, 15.0], 0.0) - 0.25).abs() < 1e-12);
        assert!((g.at([0.0, 0.0, 45.0], 0.0) - 0.4).abs() < 1e-12);
        assert!(DensityField::grade("w:0.1:0.2", &unit()).is_err());
        assert!(DensityField::grade("z:0.1", &unit()).is_err());
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.npy");
        // 2×3×2 samples: value = 0.1 + 0.1·j.
        let data: Vec<f64> = (0..12).map(|n| 0.1 + 0.1 * ((n / 2) % 3) as f64).collect();
        let mut bytes = Vec::new();
        crate::io::npy::write(&mut bytes, &[2, 3, 2], &data).unwrap();
        std::fs::write(&path, &bytes).unwrap();
        let f = DensityField::parse(path.to_str().unwrap(), &unit()).unwrap();
        assert!((f.at([5.0, 5.0, 7.0], 0.0) - 0.15).abs() < 1e-12);
        let flat = dir.path().join("flat.npy");
        let mut bytes = Vec::new();
        crate::io::npy::write(&mut bytes, &[12], &data).unwrap();
        std::fs::write(&flat, &bytes).unwrap();
        let e = DensityField::parse(flat.to_str().unwrap(), &unit())
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("shape [12]"), "{e}");
    }
}
