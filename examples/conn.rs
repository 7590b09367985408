use latvox::tpms::*;
fn main() {
    use rayon::prelude::*;
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args[1].parse().unwrap();
    let void = args[2] == "void";
    let only: Vec<String> = args[3..].to_vec();
    let jobs: Vec<(Surface, Structure)> = Surface::ALL
        .iter()
        .flat_map(|&s| [(s, Structure::Net), (s, Structure::Sheet)])
        .filter(|(s, st)| only.is_empty() || only.contains(&format!("{}-{:?}", s.name(), st)))
        .collect();
    let out: Vec<String> = jobs
        .par_iter()
        .map(|&(s, st)| {
            let r = calibrate::percolation_range(s, st, n, void);
            format!(
                "{:8} {:6} {:.4} {:.4}",
                s.name(),
                format!("{st:?}"),
                r.min,
                r.max
            )
        })
        .collect();
    for l in out {
        println!("{l}");
    }
}
