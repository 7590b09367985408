//! IGES 5.3 output: one rational B-spline curve (entity 126, form 0) per boundary loop, planar
//! in z = 0, units mm. Sections: Start, Global, Directory Entry (two lines per entity),
//! Parameter Data (columns 1–64, back-pointer to the entity's DE line in 66–72), Terminate.

use super::bspline::Periodic;
use crate::error::Result;
use std::io::Write;
use std::path::Path;

fn hollerith(s: &str) -> String {
    format!("{}H{}", s.len(), s)
}

fn num(v: f64) -> String {
    // Full precision, IGES real syntax (exponent with E).
    format!("{v:.15E}")
}

/// Lines of one section: `text` cut into `width`-column records, letter `sec` and sequence.
fn records(text: &[String], sec: char, width: usize) -> Vec<String> {
    let mut out = Vec::new();
    for t in text {
        out.push(format!("{:<width$}{}{:07}", t, sec, out.len() + 1));
    }
    out
}

/// Splits comma-separated `fields` (last one ending in `;`) into lines of at most `w` columns.
fn wrap(fields: &[String], w: usize) -> Vec<String> {
    let mut lines = Vec::new();
    let mut cur = String::new();
    for (k, f) in fields.iter().enumerate() {
        let sep = if k + 1 == fields.len() { ';' } else { ',' };
        let piece = format!("{f}{sep}");
        if !cur.is_empty() && cur.len() + piece.len() > w {
            lines.push(std::mem::take(&mut cur));
        }
        cur.push_str(&piece);
    }
    if !cur.is_empty() {
        lines.push(cur);
    }
    lines
}

/// Writes `curves` (mm) to the IGES file `path`, atomically, named after the file and stamped
/// with the time of writing.
pub fn write_file(path: &Path, curves: &[Periodic]) -> Result<()> {
    let name = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let stamp = stamp(std::time::SystemTime::now());
    crate::io::atomic::write_atomic(path, |w| write(w, curves, &name, &stamp))
}

/// The IGES time stamp of `t`: `YYYYMMDD.HHMMSS`, UTC.
pub fn stamp(t: std::time::SystemTime) -> String {
    let secs = t
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0);
    let (days, rem) = (secs / 86_400, secs % 86_400);
    // Civil date from days since 1970-01-01 (Howard Hinnant's algorithm).
    let z = days as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}{month:02}{day:02}.{:02}{:02}{:02}",
        rem / 3600,
        (rem / 60) % 60,
        rem % 60
    )
}

/// Writes `curves` (mm) as IGES. `name` goes into the header; `stamp` is the
/// `YYYYMMDD.HHMMSS` time of writing.
pub fn write(
    w: &mut dyn Write,
    curves: &[Periodic],
    name: &str,
    stamp: &str,
) -> std::io::Result<()> {
    let start = vec![format!(
        "latvox: {} closed cubic B-spline boundary curve(s), units mm",
        curves.len()
    )];
    let max_coord = curves
        .iter()
        .flat_map(|c| c.points.iter())
        .fold(1.0f64, |m, p| m.max(p[0].abs()).max(p[1].abs()));
    let global_fields: Vec<String> = vec![
        "1H,".into(),
        "1H;".into(),
        hollerith("latvox"),
        hollerith(name),
        hollerith("latvox"),
        hollerith(env!("CARGO_PKG_VERSION")),
        "32".into(),
        "38".into(),
        "6".into(),
        "308".into(),
        "15".into(),
        hollerith("latvox"),
        "1.0".into(),
        "2".into(),
        hollerith("MM"),
        "1".into(),
        "0.1".into(),
        hollerith(stamp),
        "1.0E-6".into(),
        num(max_coord),
        hollerith("latvox"),
        hollerith("latvox"),
        "11".into(),
        "0".into(),
        hollerith(stamp),
    ];
    let global = wrap(&global_fields, 72);

    // Parameter data per curve, then the directory entries pointing at it.
    let mut params: Vec<String> = Vec::new();
    let mut dir: Vec<String> = Vec::new();
    for (i, c) in curves.iter().enumerate() {
        let (knots, pts, range) = c.unwrapped();
        let k = pts.len() - 1;
        let mut f: Vec<String> = vec![
            "126".into(),
            k.to_string(),
            "3".into(),
            "1".into(), // planar
            "1".into(), // closed
            "1".into(), // polynomial (all weights 1)
            "0".into(), // non-periodic form
        ];
        f.extend(knots.iter().map(|&t| num(t)));
        f.extend((0..=k).map(|_| "1.0".to_string()));
        for p in &pts {
            f.extend([num(p[0]), num(p[1]), "0.0".into()]);
        }
        f.extend([
            num(range[0]),
            num(range[1]),
            "0.0".into(),
            "0.0".into(),
            "1.0".into(),
        ]);
        let de_line = 2 * i + 1;
        let first = params.len() + 1;
        let lines = wrap(&f, 64);
        let count = lines.len();
        for l in lines {
            params.push(format!("{l:<64} {de_line:>7}"));
        }
        dir.push(format!(
            "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}",
            126, first, 0, 1, 0, 0, 0, 0, "00000000"
        ));
        dir.push(format!(
            "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}",
            126,
            0,
            0,
            count,
            0,
            "",
            "",
            format!("LOOP{}", i + 1),
            0
        ));
    }
    let s = records(&start, 'S', 72);
    let g = records(&global, 'G', 72);
    let d = records(&dir, 'D', 72);
    let p = records(&params, 'P', 72);
    let t = records(
        &[format!(
            "S{:07}G{:07}D{:07}P{:07}",
            s.len(),
            g.len(),
            d.len(),
            p.len()
        )],
        'T',
        72,
    );
    for line in s.iter().chain(&g).chain(&d).chain(&p).chain(&t) {
        writeln!(w, "{line}")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn stamp_is_the_utc_date_and_time() {
        let t = std::time::UNIX_EPOCH + std::time::Duration::from_secs(1_519_907_696);
        assert_eq!(super::stamp(t), "20180301.123456");
        assert_eq!(super::stamp(std::time::UNIX_EPOCH), "19700101.000000");
    }
}
