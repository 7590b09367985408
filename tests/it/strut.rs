//! Strut lattices as a library user makes them: every built-in cell at densities 0.1, 0.2 and
//! 0.3 in a block of 3×3×3 cells at 32 voxels per cell (the resolution fixed, so a cell that
//! needed more would fail here), its radius found for the density on the part by the strut
//! job, written, and measured here with the tests' own code (volume by the divergence theorem,
//! edges by hash map, pieces by shared corners); CGAL's checks from the job's report.

use crate::common;

use crate::common::*;
use latvox::field::{Aabb, Domain};
use latvox::io::sink::MeshCollector;
use latvox::mesh::pipeline::Options;
use latvox::progress::Progress;
use latvox::strut::{Sizing, StrutJob, StrutLattice, UnitCell};
use std::sync::Arc;

/// The part's triangles, as the tests' own type.
fn triangles(c: &MeshCollector) -> Vec<Tri> {
    let p = |i: u32| {
        let k = 3 * i as usize;
        [0, 1, 2].map(|a| c.mesh.positions[k + a] as f64)
    };
    c.mesh
        .indices
        .chunks_exact(3)
        .map(|t| [p(t[0]), p(t[1]), p(t[2])])
        .collect()
}

/// The main tier makes every built-in cell at one of the three densities (each in turn); the long
/// tier, at the other two.
#[test]
fn every_built_in_cell_meets_a_density_closed_and_in_one_piece() {
    built_in_cells(false);
}

#[test]
#[ignore = "long: every built-in cell at the two densities the main tier leaves, checked by CGAL"]
fn every_built_in_cell_meets_its_density_closed_and_in_one_piece() {
    built_in_cells(true);
}

fn built_in_cells(all: bool) {
    let cell_size = 5.0;
    let voxel = cell_size / 32.0;
    let domain = Domain::from_cells([3; 3], [cell_size; 3], [1.5, -2.0, 0.25]).unwrap();
    let bounds = domain.bounds();
    let mut failures = Vec::new();
    for (turn, name) in latvox::strut::cell::BUILT_IN.iter().enumerate() {
        for (t, &target) in [0.1, 0.2, 0.3].iter().enumerate() {
            // The main tier's density in turn; the long tier's, the other two.
            if all == (t == turn % 3) {
                continue;
            }
            let job = StrutJob {
                grading: None,
                cell: Arc::new(UnitCell::built_in(name).unwrap()),
                cell_name: name.to_string(),
                sizing: Sizing::Density(target),
                blend: 0.0,
                domain,
                resolution: 32,
                auto_resolution: false,
                options: Options {
                    verify: latvox::verify::Verify::Cgal,
                    instancing: true,
                    ..Default::default()
                },
            };
            let mut sink = MeshCollector::default();
            let report = job.run_into(&Progress::hidden(), &mut sink).unwrap();
            let tris = triangles(&sink);
            let fraction = volume(&tris) / 15f64.powi(3);
            let e = edges(&tris);
            let (lo, hi) = common::bounds(&tris);
            let box_off = (0..3)
                .map(|a| {
                    (lo[a] - bounds.min[a])
                        .abs()
                        .max((hi[a] - bounds.max[a]).abs())
                })
                .fold(0.0, f64::max);
            let ctx = format!("{name} at {target} (radius {:.4} mm)", report.radius);
            if (fraction - target).abs() > 0.002 {
                failures.push(format!("{ctx}: density {fraction:.5}"));
            }
            if e.boundary + e.non_manifold + e.same_direction > 0 {
                failures.push(format!("{ctx}: edges {e:?}"));
            }
            if !report.part.checks.verdict().is_valid_solid() {
                failures.push(format!("{ctx}: CGAL finds {:?}", report.part.checks));
            }
            let n = pieces(&tris);
            if n != 1 {
                failures.push(format!("{ctx}: {n} pieces"));
            }
            if box_off > 0.5 * voxel {
                failures.push(format!("{ctx}: the box is {box_off:.4} mm off"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A cell file that draws bcc's struts (in another order, from other nodes) is bcc: the same
/// part to 1e-6 in volume.
#[test]
fn a_custom_cell_that_repeats_bcc_gives_bccs_volume() {
    let custom = UnitCell::from_json(
        r#"{"nodes": [[1,1,1],[0.5,0.5,0.5],[0,0,0],[1,0,0],[0,1,0],[1,1,0],[0,0,1],[1,0,1],[0,1,1]],
            "struts": [[1,0],[2,1],[1,3],[4,1],[1,5],[6,1],[1,7],[8,1]]}"#,
    )
    .unwrap();
    let bounds = Aabb {
        min: [0.0; 3],
        max: [15.0; 3],
    };
    let volume_of = |cell: UnitCell| {
        let part = StrutLattice {
            cell: Arc::new(cell),
            size: [5.0; 3],
            radius: 0.5,
            blend: 0.0,
            bounds,
            phase: bounds.min,
        };
        let (mesh, _) = latvox::mesh::pipeline::mesh_keyed(
            &part,
            latvox::mesh::pipeline::part_spec(&part, 5.0 / 32.0),
            None,
            0.0,
            None,
        )
        .unwrap();
        let m = mesh.into_mesh();
        let p = |i: u32| {
            let k = 3 * i as usize;
            [0, 1, 2].map(|a| m.positions[k + a] as f64)
        };
        let tris: Vec<Tri> = m
            .indices
            .chunks_exact(3)
            .map(|t| [p(t[0]), p(t[1]), p(t[2])])
            .collect();
        volume(&tris)
    };
    let a = volume_of(UnitCell::built_in("bcc").unwrap());
    let b = volume_of(custom);
    assert!(
        (a - b).abs() <= 1e-6 * a,
        "bcc {a} mm³, the cell file {b} mm³"
    );
}

/// Where thin struts meet the box, two rim vertices snapped onto a face from neighbouring cells
/// can swap places along it: an octet truss at 15 % in this box once wrote crossing triangles on
/// its x face. CGAL finds the written part free of self-intersections.
#[test]
fn thin_struts_cut_by_the_box_leave_no_crossing_triangles() {
    let dir = tempdir();
    ok(
        &[
            "strut",
            "--cell",
            "octet",
            "--density",
            "0.15",
            "--size",
            "11.514829069883385,10.813838866363737,12.649712343566318",
            "--cell-size",
            "4.80342141536725",
            "--origin",
            "14.48609766145924,-11.05265645115535,-8.790671405272938",
            "-r",
            "22",
            "--no-instancing",
            "--verify",
            "cgal",
            "-q",
            "-o",
            "part.stl",
            "--report",
            "part.json",
        ],
        dir.path(),
    );
    let r = json(&dir.path().join("part.json"));
    assert_eq!(r["checks"]["checked_by"], "CGAL");
    assert_eq!(r["checks"]["self_intersecting"], false);
    assert_eq!(r["checks"]["closed"], true);
}
