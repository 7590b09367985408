use latvox::field::*;
use latvox::grid::*;
use latvox::tpms::*;
use std::time::Instant;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let cells: f64 = args.get(1).map(|s| s.parse().unwrap()).unwrap_or(3.0);
    let res: f64 = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(32.0);
    let only: Option<String> = args.get(3).cloned();
    let a = 5.0;
    for s in Surface::ALL {
        if let Some(o) = &only { if s.name() != o { continue; } }
        for st in [Structure::Net, Structure::Sheet] {
            for target in [0.1, 0.2, 0.3, 0.5] {
                let t0 = Instant::now();
                let t = calibrate::level_for(s, st, target);
                let tc = t0.elapsed();
                let h = a / res;
                let bounds = Aabb { min: [0.0; 3], max: [a * cells; 3] };
                let f = Intersection { a: TpmsField::new(s, st, t, [a; 3], [0.0; 3], 3.0 * h), b: bounds };
                let spec = GridSpec::covering(&bounds, h, 3.0);
                let t1 = Instant::now();
                let g = Grid::sample(&f, spec).unwrap();
                let ts = t1.elapsed();
                let t2 = Instant::now();
                let m = g.to_mesh(0.0).unwrap();
                let tm = t2.elapsed();
                let vf = m.volume() / bounds.volume();
                let es = m.edge_stats();
                println!("{:8} {:?} target {target} level {t:.4} vf {vf:.5} err {:+.5} tris {} bnd {} nm {} mis {} cal {:?} samp {:?} mesh {:?}",
                    s.name(), st, vf - target, m.triangle_count(), es.boundary, es.non_manifold, es.misoriented, tc, ts, tm);
                if args.get(4).is_some() {
                    let v = latvox::verify::verify(&m, true).unwrap();
                    println!("   {:?}", v);
                }
            }
        }
    }
}
