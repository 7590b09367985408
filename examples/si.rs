use latvox::tpms::*;
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let m = latvox::stl::read(std::path::Path::new(&a[1])).unwrap();
    let pairs = latvox::verify::self_intersections(&m, 20).unwrap();
    println!("{} pairs", pairs.len());
    for (f, g) in pairs.iter().take(6) {
        println!(
            "f{f}: {:?}\n f{g}: {:?}",
            m.triangle(*f as usize),
            m.triangle(*g as usize)
        );
    }
    let _ = Surface::ALL;
}
