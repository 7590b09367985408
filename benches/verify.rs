//! Verification benchmarks (work in progress).
use latvox::io::ReadOptions;
use std::time::Instant;

fn main() {
    let path = std::env::args()
        .skip(1)
        .find(|a| !a.starts_with('-'))
        .unwrap_or("/tmp/dnet.stl".into());
    let mesh = latvox::io::read(std::path::Path::new(&path), &ReadOptions::default())
        .unwrap()
        .mesh;
    let all: Vec<u32> = (0..mesh.triangle_count() as u32).collect();
    let t = Instant::now();
    let ours = latvox::check::self_intersect::soup_self_intersections(&mesh, &all, 16);
    println!("latvox {:.3} s  {:?}", t.elapsed().as_secs_f64(), ours.0);
    if std::env::args().any(|a| a == "--cgal") {
        let t = Instant::now();
        let c = latvox::check::self_intersect::cgal_soup_self_intersections(&mesh, &all, None, 16)
            .unwrap();
        println!("cgal {:.3} s  {:?}", t.elapsed().as_secs_f64(), c.0);
        assert_eq!(c, ours);
    }
}
