use latvox::field::*;
use latvox::tpms::*;
use std::time::Instant;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let cells: f64 = args.get(1).map(|s| s.parse().unwrap()).unwrap_or(3.0);
    let res: f64 = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(32.0);
    let only: Option<String> = args.get(3).cloned();
    let a = 5.0;
    for s in Surface::ALL {
        if let Some(o) = &only {
            if s.name() != o {
                continue;
            }
        }
        for st in [Structure::Net, Structure::Sheet] {
            let t0 = Instant::now();
            let r = calibrate::feasible_range(s, st);
            println!(
                "{} {:?} feasible {:?} ({:?})",
                s.name(),
                st,
                r,
                t0.elapsed()
            );
            for target in [0.1, 0.2, 0.3, 0.5] {
                let h = a / res;
                let t0 = Instant::now();
                let c = match calibrate::calibrate(s, st, target, [a; 3], h, [cells; 3], 0.0) {
                    Ok(c) => c,
                    Err(e) => {
                        println!("   {target}: {e}");
                        continue;
                    }
                };
                let tc = t0.elapsed();
                let bounds = Aabb {
                    min: [0.0; 3],
                    max: [a * cells; 3],
                };
                let l = Lattice {
                    surface: s,
                    structure: st,
                    level: c.level,
                    cell: [a; 3],
                    bounds,
                    phase: [0.0; 3],
                };
                let (m, ms) = l.mesh(h, 0.0).unwrap();
                let vf = m.volume() / bounds.volume();
                let wall = if st == Structure::Sheet {
                    calibrate::thinnest_sheet_wall(s, c.level) * res
                } else {
                    f64::NAN
                };
                println!("   {target}: err {:+.5} pred {:+.5} analytic {:+.4}->{:+.4} wall {wall:.2}vox meshings {} cal {:?} kept {}",
                    vf - target, c.predicted_fraction - target, c.analytic_level, c.level, c.meshings, tc, ms.snap.kept);
            }
        }
    }
}
