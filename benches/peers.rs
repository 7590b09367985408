//! latvox against native-Rust meshers, side by side, with the figures quoted in README.
//!
//! One field, one grid: the gyroid net at density 0.30 (level `t` from latvox's calibration at
//! each resolution), 2×2×2 cells of 5 mm, clipped by its box, sampled at the voxel centres
//! `min + (i + ½)·h` with `h = 5 mm / resolution`, for 32, 64 and 128 voxels per cell. Every
//! mesher meshes the same values: latvox's `TpmsField ∩ Aabb` (first-order distance to the
//! gyroid, `max`-ed with the box's exact distance, so the solid is closed at the cut faces).
//! Then a larger part, 8×8×8 cells at 32 voxels per cell (`--large N`, 0 to skip), where
//! latvox's job copies cells from a meshed 3×3×3-cell template.
//!
//! - `latvox job`: the whole `latvox tpms` path in-process ([`TpmsJob::run_into`]): calibrate,
//!   sample the narrow band, OpenVDB volumeToMesh, snap, CGAL's checks (self-intersection
//!   included), binary STL streamed to a file.
//! - `latvox mesh`: sample + mesh only ([`Lattice::mesh`]): narrow band (8³ blocks culled by the
//!   field's clearance, sampled with rayon), OpenVDB volumeToMesh, snapping onto the surface and
//!   the box's edges; an indexed mesh in memory.
//! - `fast-surface-nets` and `mcubes`: they mesh a dense array. It is sampled by the same
//!   `Field::sample_block` code latvox uses (8³ blocks, rayon over z-slabs) on the box plus two
//!   samples outside each face (positive there, so their surfaces close too); its time is given
//!   apart ("sample") from the crate's own ("mesh": the crate call plus turning its output into
//!   an indexed mesh in millimetres, with no welding). Both crates mesh on one thread.
//!
//! Each run is a fresh child process (this binary re-run with `--child`): wall time and CPU time
//! (user + system, all threads, `getrusage`) of the case, and its peak resident memory (`VmHWM`
//! read right after the case, before any check). Medians of `--runs` runs (3). The first run of
//! each case also checks the mesh, untimed: vertices welded exactly (bit-identical f32
//! coordinates), then every edge counted here — boundary edges (one triangle), non-manifold
//! edges (three or more), edges whose two triangles run the same way — degenerate triangles
//! (a repeated welded vertex), the enclosed volume, each vertex's distance to the exact surface;
//! the edges again after welding within [`NEAR_WELD`]; and CGAL's checks (`latvox::verify::cgal`, with
//! the self-intersection test) on the welded mesh (not on the larger part's meshes). The job's
//! mesh is checked as written: its STL file is read back here; its CGAL checks are its own.
//!
//! Run: `cargo bench --bench peers` (`-- --runs N --res 32,64 --cells N --large N`).

use latvox::field::{Field, Intersection};
use latvox::geom::Mesh;
use latvox::grid::GridSpec;
use latvox::tpms::{calibrate, Domain, Lattice, Structure, Surface, TpmsJob, HALF_WIDTH};
use rayon::prelude::*;
use serde_json::{json, Value};
use std::collections::HashMap;
use std::process::Command;
use std::time::Instant;

const CELL: f64 = 5.0;
const DENSITY: f64 = 0.3;
/// Dense samples outside each box face. One makes the clipped field positive all round the
/// array; fast-surface-nets needs two, as it makes no faces in the array's last layer of voxels
/// (left to the next chunk, so that chunks join without seams).
const PAD: i64 = 2;
/// Grid for welding near matches, mm (1/3900 of the finest voxel here).
const NEAR_WELD: f64 = 1e-5;
const CASES: [&str; 4] = ["latvox job", "latvox mesh", "fast-surface-nets", "mcubes"];

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--child") {
        child(&args[i + 1..]);
        return;
    }
    let opt = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let runs: usize = opt("--runs").map_or(3, |s| s.parse().expect("--runs N"));
    let cells: u32 = opt("--cells").map_or(2, |s| s.parse().expect("--cells N"));
    let resolutions: Vec<u32> = opt("--res").map_or(vec![32, 64, 128], |s| {
        s.split(',')
            .map(|r| r.parse().expect("--res 32,64"))
            .collect()
    });
    let large: u32 = opt("--large").map_or(8, |s| s.parse().expect("--large N"));
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!(
        "gyroid net, density {DENSITY}, cells of {CELL} mm; {threads} threads; {runs} runs per case (fresh process each), medians; load average at start: {}",
        load_average()
    );
    let exe = std::env::current_exe().expect("own path");
    let spawn = |case: &str, cells: u32, res: u32, level: f64, mode: &str| -> Value {
        let out = Command::new(&exe)
            .args(["--child", case, &res.to_string(), &cells.to_string()])
            .arg(format!("{:016x}", level.to_bits()))
            .arg(mode)
            .stderr(std::process::Stdio::inherit())
            .output()
            .expect("spawn the bench binary");
        assert!(out.status.success(), "{case} at {res} failed");
        let line = String::from_utf8(out.stdout).expect("utf-8");
        serde_json::from_str(line.trim()).expect("one JSON line from the child")
    };

    let idle = spawn("idle", 1, 32, 0.0, "time");
    println!(
        "a child that does nothing: peak RSS {:.0} MB (included in every figure below)",
        idle["hwm_mb"].as_f64().unwrap()
    );
    // The comparison at three resolutions; then a larger part at the lowest one, where latvox
    // copies cells from a meshed template (CGAL's checks skipped for the peer's big mesh).
    let mut parts: Vec<(u32, u32, &[&str], &str)> = resolutions
        .iter()
        .map(|&r| (cells, r, &CASES[..], "check"))
        .collect();
    if large > 0 {
        parts.push((large, resolutions[0], &CASES[..3], "check-quick"));
    }
    let mut rows = Vec::new();
    for (cells, res, cases, check) in parts {
        let voxel = CELL / res as f64;
        let cal = calibrate::calibrate(
            Surface::Gyroid,
            Structure::Net,
            DENSITY,
            [CELL; 3],
            voxel,
            [cells as f64; 3],
            0.0,
        )
        .expect("calibration");
        let n = cells as i64 * res as i64 + 2 * PAD;
        println!(
            "\n{cells}x{cells}x{cells} cells, {res} voxels per cell: level t = {:.6}; dense array {n}^3 = {:.1} M samples ({:.0} MB as f32)",
            cal.level,
            (n * n * n) as f64 / 1e6,
            (n * n * n * 4) as f64 / 1e6
        );
        for &case in cases {
            let results: Vec<Value> = (0..runs)
                .map(|r| {
                    spawn(
                        case,
                        cells,
                        res,
                        cal.level,
                        if r == 0 { check } else { "time" },
                    )
                })
                .collect();
            let med = |key: &str| {
                let v: Vec<f64> = results.iter().filter_map(|r| r[key].as_f64()).collect();
                (!v.is_empty()).then(|| median(v))
            };
            let first = &results[0];
            let row = json!({
                "part": format!("{cells}³ × {res}"),
                "case": case,
                "wall": med("wall"),
                "cpu": med("cpu"),
                "sample": med("sample"),
                "mesh": med("mesh"),
                "snap": med("snap"),
                "hwm_mb": med("hwm_mb"),
                "triangles": first["triangles"],
                "check": first["check"],
                "stages": median_stages(&results),
                "job_checks": first["job_checks"],
                "instanced": first["instanced"],
                "level": first["level"],
            });
            if case == "latvox job" {
                assert_eq!(row["level"].as_f64(), Some(cal.level), "the job's level");
            }
            print_row(&row);
            rows.push(row);
        }
    }
    println!("\nload average at the end: {}", load_average());
    print_table(&rows);
}

/// One case in this process; prints one JSON line.
fn child(a: &[String]) {
    let case = a[0].as_str();
    let res: u32 = a[1].parse().unwrap();
    let cells: u32 = a[2].parse().unwrap();
    let level = f64::from_bits(u64::from_str_radix(&a[3], 16).unwrap());
    let check = a[4].starts_with("check");
    let cgal = a[4] == "check";
    // Start rayon's pool before the clock, for every case alike.
    let _: u64 = (0..1000u64).into_par_iter().sum();

    let domain = Domain::from_cells([cells; 3], [CELL; 3], [0.0; 3]).unwrap();
    let bounds = domain.bounds();
    let voxel = CELL / res as f64;
    let lattice = Lattice {
        surface: Surface::Gyroid,
        structure: Structure::Net,
        level,
        cell: [CELL; 3],
        bounds,
        phase: bounds.min,
    };
    let dir = tempfile::tempdir().unwrap();
    let stl = dir.path().join("part.stl");

    let cpu0 = cpu_seconds();
    let t0 = Instant::now();
    let mut out = serde_json::Map::new();
    let mesh: Option<Mesh> = match case {
        "idle" => None,
        "latvox job" => {
            let job = TpmsJob {
                surface: Surface::Gyroid,
                structure: Structure::Net,
                density: DENSITY,
                domain,
                resolution: res,
                adaptivity: 0.0,
                tolerance: None,
                allow_islands: false,
                auto_resolution: true,
                verify: latvox::verify::Verify::Full,
                instancing: true,
                tile: None,
                memory: None,
                keep_fragments: false,
                grading: None,
                blend: None,
                cell_map: None,
            };
            let mut sink =
                latvox::io::sink::StlSink::create(&stl, latvox::io::StlFormat::Binary).unwrap();
            let report = job
                .run_into(&latvox::progress::Progress::hidden(), &mut sink)
                .unwrap();
            sink.commit().unwrap();
            out.insert("triangles".into(), json!(report.part.triangles));
            out.insert("level".into(), json!(report.level));
            out.insert("stages".into(), json!(report.part.timings));
            out.insert("job_checks".into(), json!(report.part.checks));
            out.insert("instanced".into(), json!(report.part.instancing));
            None
        }
        "latvox mesh" => {
            let (m, stats) = lattice.mesh(voxel, 0.0).unwrap();
            out.insert("sample".into(), json!(stats.sample_seconds));
            out.insert("mesh".into(), json!(stats.mesh_seconds));
            out.insert("snap".into(), json!(stats.snap_seconds));
            Some(m)
        }
        "fast-surface-nets" | "mcubes" => {
            let spec = GridSpec::covering(&bounds, voxel, HALF_WIDTH);
            let field = Intersection {
                a: lattice
                    .field(HALF_WIDTH * voxel)
                    .with_periodic_samples(voxel),
                b: bounds,
            };
            let (values, dims) = sample_dense(&field, &spec);
            let sampled = t0.elapsed().as_secs_f64();
            let m = if case == "mcubes" {
                mesh_mcubes(values, dims, &spec)
            } else {
                mesh_surface_nets(&values, dims, &spec)
            };
            out.insert("sample".into(), json!(sampled));
            out.insert("mesh".into(), json!(t0.elapsed().as_secs_f64() - sampled));
            Some(m)
        }
        other => panic!("unknown case {other}"),
    };
    let wall = t0.elapsed().as_secs_f64();
    let cpu = cpu_seconds() - cpu0;
    let hwm = vm_hwm_mb();
    out.insert("wall".into(), json!(wall));
    out.insert("cpu".into(), json!(cpu));
    out.insert("hwm_mb".into(), json!(hwm));
    if let Some(m) = &mesh {
        out.insert("triangles".into(), json!(m.triangle_count()));
    }
    if check && case != "idle" {
        let m = match mesh {
            Some(m) => m,
            None => read_binary_stl(&std::fs::read(&stl).unwrap()),
        };
        // The surface every mesher was given, evaluated exactly (no sample periodicity, no clamp
        // near the surface): the gyroid's first-order distance, max-ed with the box's distance.
        let surface = Intersection {
            a: lattice.field(CELL),
            b: bounds,
        };
        // The job's own report holds CGAL's checks of the mesh it wrote.
        let cgal = cgal && case != "latvox job";
        out.insert(
            "check".into(),
            check_mesh(&m, &surface, voxel, bounds.volume(), cgal),
        );
    }
    println!("{}", Value::Object(out));
}

/// The field on the box's voxel centres and one sample beyond each face, as a dense array with
/// x varying fastest (the layout both crates read). Sampled in 8³ blocks by the field's own
/// block sampler, in parallel over slabs of 8 z-layers.
fn sample_dense(field: &dyn Field, spec: &GridSpec) -> (Vec<f32>, [usize; 3]) {
    let d = spec.dims.map(|n| (n + 2 * PAD) as usize);
    let mut values = vec![0.0f32; d[0] * d[1] * d[2]];
    let slab = 8 * d[0] * d[1];
    values
        .par_chunks_mut(slab)
        .enumerate()
        .for_each(|(bz, out)| {
            let mut block = [0.0f32; 512];
            for by in 0..d[1].div_ceil(8) {
                for bx in 0..d[0].div_ceil(8) {
                    let first = [bx * 8, by * 8, bz * 8];
                    let origin = spec.point(first.map(|s| s as i64 - PAD));
                    field.sample_block(origin, spec.voxel, &mut block);
                    for i in 0..8.min(d[0] - first[0]) {
                        for j in 0..8.min(d[1] - first[1]) {
                            for k in 0..8.min(d[2] - first[2]) {
                                let (x, y) = (first[0] + i, first[1] + j);
                                out[x + d[0] * (y + d[1] * k)] = block[(i * 8 + j) * 8 + k];
                            }
                        }
                    }
                }
            }
        });
    (values, d)
}

/// Dense array index `s` (along one axis) to millimetres.
fn world(spec: &GridSpec, a: usize, s: f64) -> f32 {
    (spec.origin[a] + (s - PAD as f64 + 0.5) * spec.voxel) as f32
}

fn mesh_surface_nets(values: &[f32], d: [usize; 3], spec: &GridSpec) -> Mesh {
    use fast_surface_nets::{ndshape::RuntimeShape, surface_nets, SurfaceNetsBuffer};
    let shape = RuntimeShape::<u32, 3>::new(d.map(|n| n as u32));
    let mut buf = SurfaceNetsBuffer::default();
    let max = d.map(|n| n as u32 - 1);
    surface_nets(values, &shape, [0; 3], max, &mut buf);
    let positions = buf
        .positions
        .iter()
        .flat_map(|p| [0, 1, 2].map(|a| world(spec, a, p[a] as f64)))
        .collect();
    // Wound outward for a field negative inside, as it comes.
    Mesh {
        positions,
        indices: std::mem::take(&mut buf.indices),
    }
}

fn mesh_mcubes(values: Vec<f32>, d: [usize; 3], spec: &GridSpec) -> Mesh {
    use mcubes::{MarchingCubes, MeshSide};
    let h = spec.voxel as f32;
    let offset = lin_alg::f32::Vec3::new(
        world(spec, 0, 0.0),
        world(spec, 1, 0.0),
        world(spec, 2, 0.0),
    );
    let mc = MarchingCubes::new(
        (d[0], d[1], d[2]),
        (h, h, h),
        (1.0, 1.0, 1.0),
        offset,
        values,
        0.0,
    )
    .expect("dims match the array");
    let m = mc.generate(MeshSide::OutsideOnly);
    Mesh {
        positions: m
            .vertices
            .iter()
            .flat_map(|v| [v.posit.x, v.posit.y, v.posit.z])
            .collect(),
        indices: m.indices.iter().map(|&i| i as u32).collect(),
    }
}

/// Welds vertices: one per distinct f32 triple (−0 and +0 are one), or with `tolerance` (mm),
/// a vertex joins an earlier one within that distance along every axis. Triangles left with a
/// repeated vertex are dropped and counted.
fn weld(m: &Mesh, tolerance: Option<f64>) -> (Mesh, u64) {
    let mut exact: HashMap<[u32; 3], u32> = HashMap::new();
    let mut near: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    let mut positions: Vec<f32> = Vec::new();
    let remap: Vec<u32> = m
        .positions
        .chunks_exact(3)
        .map(|p| {
            let next = (positions.len() / 3) as u32;
            let id = match tolerance {
                None => *exact
                    .entry([0, 1, 2].map(|a| (p[a] + 0.0).to_bits()))
                    .or_insert(next),
                Some(q) => {
                    let cell = [0, 1, 2].map(|a| (p[a] as f64 / q).floor() as i64);
                    let close = |&v: &u32| {
                        (0..3).all(|a| {
                            (positions[3 * v as usize + a] as f64 - p[a] as f64).abs() <= q
                        })
                    };
                    let mut found = None;
                    'search: for dx in -1..=1 {
                        for dy in -1..=1 {
                            for dz in -1..=1 {
                                let c = [cell[0] + dx, cell[1] + dy, cell[2] + dz];
                                if let Some(v) =
                                    near.get(&c).and_then(|l| l.iter().find(|v| close(v)))
                                {
                                    found = Some(*v);
                                    break 'search;
                                }
                            }
                        }
                    }
                    found.unwrap_or_else(|| {
                        near.entry(cell).or_default().push(next);
                        next
                    })
                }
            };
            if id == next {
                positions.extend_from_slice(p);
            }
            id
        })
        .collect();
    let mut indices = Vec::with_capacity(m.indices.len());
    let mut degenerate = 0u64;
    for t in m.indices.chunks_exact(3) {
        let w = [
            remap[t[0] as usize],
            remap[t[1] as usize],
            remap[t[2] as usize],
        ];
        if w[0] == w[1] || w[1] == w[2] || w[0] == w[2] {
            degenerate += 1;
        } else {
            indices.extend_from_slice(&w);
        }
    }
    (Mesh { positions, indices }, degenerate)
}

/// Edge counts of a welded mesh: (edges, boundary, non-manifold, same-way).
fn edge_counts(m: &Mesh) -> [u64; 4] {
    // Key (lo << 32 | hi), with the direction kept apart.
    let mut half: Vec<(u64, bool)> = m
        .indices
        .par_chunks_exact(3)
        .flat_map_iter(|t| {
            (0..3).map(move |k| {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                (((a.min(b) as u64) << 32) | a.max(b) as u64, a < b)
            })
        })
        .collect();
    half.par_sort_unstable();
    let mut n = [0u64; 4];
    for run in half.chunk_by(|x, y| x.0 == y.0) {
        n[0] += 1;
        match run.len() {
            1 => n[1] += 1,
            2 if run[0].1 == run[1].1 => n[3] += 1,
            2 => {}
            _ => n[2] += 1,
        }
    }
    n
}

/// Exact welding, edge counts and volume, computed here (not by latvox), then CGAL's checks on
/// the welded mesh; and all again after welding within [`NEAR_WELD`].
fn check_mesh(m: &Mesh, exact: &dyn Field, voxel: f64, box_volume: f64, cgal: bool) -> Value {
    let (welded, degenerate) = weld(m, None);
    // How far the vertices lie from the surface they stand for, in voxels.
    let errors: Vec<f64> = welded
        .positions
        .par_chunks_exact(3)
        .map(|p| exact.value([0, 1, 2].map(|a| p[a] as f64)).abs() / voxel)
        .collect();
    let mut sorted = errors;
    sorted.par_sort_unstable_by(|a, b| a.total_cmp(b));
    let quantile = |q: f64| sorted[((sorted.len() - 1) as f64 * q).round() as usize];
    let [edges, boundary, non_manifold, same_way] = edge_counts(&welded);
    let p = |i: u32| {
        let i = 3 * i as usize;
        [0, 1, 2].map(|a| welded.positions[i + a] as f64)
    };
    let volume: f64 = welded
        .indices
        .par_chunks_exact(3)
        .map(|t| {
            let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum();
    let t = Instant::now();
    let cgal = cgal.then(|| latvox::verify::cgal::verify(&welded, true).expect("CGAL check"));
    let cgal_seconds = t.elapsed().as_secs_f64();
    let (near, near_degenerate) = weld(m, Some(NEAR_WELD));
    let [_, near_boundary, near_non_manifold, near_same_way] = edge_counts(&near);
    // CGAL again on the nearly welded mesh when that one closes and the exact one did not.
    let near_cgal = (cgal.is_some() && boundary > 0 && near_boundary == 0)
        .then(|| latvox::verify::cgal::verify(&near, true).expect("CGAL check"));
    json!({
        "vertices": welded.vertex_count(),
        "degenerate": degenerate,
        "edges": edges,
        "boundary": boundary,
        "non_manifold": non_manifold,
        "same_way": same_way,
        "density": volume / box_volume,
        "error_median": quantile(0.5),
        "error_p99": quantile(0.99),
        "error_max": quantile(1.0),
        "cgal": cgal,
        "cgal_seconds": cgal_seconds,
        "near_weld": {
            "vertices": near.vertex_count(),
            "degenerate": near_degenerate,
            "boundary": near_boundary,
            "non_manifold": near_non_manifold,
            "same_way": near_same_way,
            "cgal": near_cgal,
        },
    })
}

fn read_binary_stl(b: &[u8]) -> Mesh {
    let n = u32::from_le_bytes(b[80..84].try_into().unwrap()) as usize;
    assert_eq!(b.len(), 84 + 50 * n, "binary STL size");
    let mut positions = Vec::with_capacity(9 * n);
    for t in 0..n {
        let f = &b[84 + 50 * t + 12..84 + 50 * t + 48];
        positions.extend(
            f.chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().unwrap())),
        );
    }
    Mesh {
        positions,
        indices: (0..3 * n as u32).collect(),
    }
}

fn cpu_seconds() -> f64 {
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: getrusage on this process with a valid out-pointer.
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    let tv = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    tv(u.ru_utime) + tv(u.ru_stime)
}

/// Peak resident set of this process so far, MB.
fn vm_hwm_mb() -> f64 {
    let s = std::fs::read_to_string("/proc/self/status").unwrap();
    let line = s.lines().find(|l| l.starts_with("VmHWM:")).unwrap();
    let kb: f64 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
    kb / 1024.0
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_default()
}

/// The job's stage times, each the median over the runs.
fn median_stages(results: &[Value]) -> Value {
    let Some(first) = results[0]["stages"].as_object() else {
        return Value::Null;
    };
    let stages = first.keys().map(|k| {
        let v = results
            .iter()
            .map(|r| r["stages"][k].as_f64().unwrap())
            .collect();
        (k.clone(), json!(median(v)))
    });
    Value::Object(stages.collect())
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn print_row(r: &Value) {
    let f = |k: &str| r[k].as_f64().map_or("-".into(), |x| format!("{x:.3}"));
    println!(
        "  {:18} wall {} s (sample {}, mesh {}, snap {}), CPU {} s, peak RSS {:.0} MB, {} triangles",
        r["case"].as_str().unwrap(),
        f("wall"),
        f("sample"),
        f("mesh"),
        f("snap"),
        f("cpu"),
        r["hwm_mb"].as_f64().unwrap(),
        r["triangles"]
    );
    if !r["instanced"].is_null() {
        println!("      instanced: {}", r["instanced"]);
    }
    if !r["stages"].is_null() {
        println!("      job stages, medians (s): {}", r["stages"]);
        println!("      job's own CGAL checks: {}", r["job_checks"]);
    }
    println!("      check: {}", r["check"]);
}

/// The README tables: speed and memory (absolute, and against latvox's sample + mesh), then what
/// each mesh is.
fn print_table(rows: &[Value]) {
    println!("\n| cells × vox/cell | mesher | wall (sample + mesh) | ÷ latvox mesh | CPU | peak RSS | ÷ latvox mesh | triangles |");
    println!("|---|---|---|---|---|---|---|---|");
    for r in rows {
        let base = rows
            .iter()
            .find(|b| b["part"] == r["part"] && b["case"] == "latvox mesh")
            .unwrap();
        let wall = r["wall"].as_f64().unwrap();
        let hwm = r["hwm_mb"].as_f64().unwrap();
        let parts = match (r["sample"].as_f64(), r["mesh"].as_f64(), r["snap"].as_f64()) {
            (Some(s), Some(m), Some(n)) => format!(" ({s:.3} + {m:.3} + snap {n:.3})"),
            (Some(s), Some(m), None) => format!(" ({s:.3} + {m:.3})"),
            _ => String::new(),
        };
        println!(
            "| {} | {} | {wall:.3} s{parts} | {:.2} | {:.3} s | {hwm:.0} MB | {:.2} | {} |",
            r["part"].as_str().unwrap(),
            r["case"].as_str().unwrap(),
            wall / base["wall"].as_f64().unwrap(),
            r["cpu"].as_f64().unwrap(),
            hwm / base["hwm_mb"].as_f64().unwrap(),
            r["triangles"],
        );
    }
    let verdict = |g: &Value| {
        if g.is_null() {
            return "-".to_string();
        }
        let yes = |b: bool| if b { "yes" } else { "no" };
        format!(
            "{}, {}, {}, {}",
            yes(g["closed"].as_bool().unwrap()),
            yes(g["manifold"].as_bool().unwrap()),
            yes(g["outward"].as_bool().unwrap()),
            yes(!g["self_intersecting"].as_bool().unwrap())
        )
    };
    println!("\n| cells × vox/cell | mesher | boundary / non-manifold edges, exact weld | within {NEAR_WELD} mm | CGAL: closed, manifold, outward, no self-intersection | volume fraction | vertex to surface (voxels): median / 99th pct. / max |");
    println!("|---|---|---|---|---|---|---|");
    for r in rows {
        let c = &r["check"];
        let n = &c["near_weld"];
        let cgal = if r["case"] == "latvox job" {
            let on = if r["instanced"].is_null() {
                ""
            } else {
                " (on the template)"
            };
            format!("{}{on}", verdict(&r["job_checks"]))
        } else if n["cgal"].is_null() {
            verdict(&c["cgal"])
        } else {
            format!(
                "{} (exact weld); {} (within {NEAR_WELD} mm)",
                verdict(&c["cgal"]),
                verdict(&n["cgal"])
            )
        };
        println!(
            "| {} | {} | {} / {} | {} / {} | {cgal} | {:.5} | {:.1e} / {:.1e} / {:.3} |",
            r["part"].as_str().unwrap(),
            r["case"].as_str().unwrap(),
            c["boundary"],
            c["non_manifold"],
            n["boundary"],
            n["non_manifold"],
            c["density"].as_f64().unwrap(),
            c["error_median"].as_f64().unwrap(),
            c["error_p99"].as_f64().unwrap(),
            c["error_max"].as_f64().unwrap(),
        );
    }
}
