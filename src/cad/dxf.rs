//! DXF output (AutoCAD 2000 group codes, millimetres): one SPLINE entity per boundary loop,
//! degree 3, with the same knots and control points as the IGES curves.

use super::bspline::Periodic;
use std::io::Write;

fn pair(w: &mut dyn Write, code: i32, value: impl std::fmt::Display) -> std::io::Result<()> {
    writeln!(w, "{code:>3}\n{value}")
}

/// Writes `curves` as a DXF file.
pub fn write(w: &mut dyn Write, curves: &[Periodic]) -> std::io::Result<()> {
    pair(w, 0, "SECTION")?;
    pair(w, 2, "HEADER")?;
    pair(w, 9, "$ACADVER")?;
    pair(w, 1, "AC1015")?;
    pair(w, 9, "$INSUNITS")?;
    pair(w, 70, 4)?; // millimetres
    pair(w, 0, "ENDSEC")?;
    pair(w, 0, "SECTION")?;
    pair(w, 2, "ENTITIES")?;
    for (i, c) in curves.iter().enumerate() {
        let (knots, pts, _) = c.unwrapped();
        pair(w, 0, "SPLINE")?;
        pair(w, 5, format!("{:X}", 0x100 + i))?;
        pair(w, 100, "AcDbEntity")?;
        pair(w, 8, "latvox")?;
        pair(w, 100, "AcDbSpline")?;
        pair(w, 210, 0.0)?;
        pair(w, 220, 0.0)?;
        pair(w, 230, 1.0)?;
        pair(w, 70, 8)?; // planar
        pair(w, 71, 3)?;
        pair(w, 72, knots.len())?;
        pair(w, 73, pts.len())?;
        pair(w, 74, 0)?;
        pair(w, 42, 1e-10)?;
        pair(w, 43, 1e-10)?;
        for k in &knots {
            pair(w, 40, format!("{k:.15e}"))?;
        }
        for p in &pts {
            pair(w, 10, format!("{:.15e}", p[0]))?;
            pair(w, 20, format!("{:.15e}", p[1]))?;
            pair(w, 30, 0.0)?;
        }
    }
    pair(w, 0, "ENDSEC")?;
    pair(w, 0, "EOF")
}
