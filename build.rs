//! Compiles the C++ shims and links the Debian packages behind them: one bridge per library
//! (`src/ffi/vdb.rs` with `cpp/vdb.h`, `src/ffi/cgal.rs` with `cpp/cgal.h`), each implemented by
//! a few small translation units so that no unit parses both OpenVDB's and CGAL's headers.

use std::path::Path;

/// The C++ headers: one per library, and what the OpenVDB units share.
const HEADERS: [&str; 3] = ["cpp/vdb.h", "cpp/vdb_internal.h", "cpp/cgal.h"];
/// The translation units behind `cpp/vdb.h`.
const VDB_UNITS: [&str; 8] = [
    "cpp/vdb_grid.cc",
    "cpp/vdb_from_mesh.cc",
    "cpp/vdb_csg.cc",
    "cpp/vdb_read.cc",
    "cpp/vdb_probe.cc",
    "cpp/vdb_filter.cc",
    "cpp/vdb_mesh.cc",
    "cpp/vdb_file.cc",
];
/// The translation units behind `cpp/cgal.h`.
const CGAL_CHECK_UNIT: &str = "cpp/cgal_check.cc";
const CGAL_REPAIR_UNIT: &str = "cpp/cgal_repair.cc";
const CGAL_BOOLEAN_UNIT: &str = "cpp/cgal_boolean.cc";
const CGAL_DISTANCE_UNIT: &str = "cpp/cgal_distance.cc";
const CGAL_VORONOI_UNIT: &str = "cpp/cgal_voronoi.cc";

const INSTALL_HINT: &str = "run `bash scripts/install-deps.sh` (Debian bookworm: libopenvdb-dev, libcgal-dev, libtbb-dev, libgmp-dev, libmpfr-dev, libeigen3-dev)";

fn require_header(name: &str) {
    let dirs = [
        "/usr/include",
        "/usr/local/include",
        "/usr/include/x86_64-linux-gnu",
        "/usr/include/aarch64-linux-gnu",
    ];
    if !dirs.iter().any(|d| Path::new(d).join(name).exists()) {
        panic!("latvox: missing C++ header <{name}>; {INSTALL_HINT}");
    }
}

fn main() {
    require_header("openvdb/openvdb.h");
    require_header("CGAL/Surface_mesh.h");
    require_header("tbb/tbb.h");
    require_header("gmp.h");
    require_header("mpfr.h");

    let flags = |b: &mut cc::Build| {
        b.std("c++17")
            .flag_if_supported("-O2")
            .flag_if_supported("-Wno-unused-parameter")
            .flag_if_supported("-Wno-deprecated-declarations")
            .flag_if_supported("-Wno-class-memaccess")
            .include("cpp")
            .include("/usr/include/eigen3");
    };

    // OpenVDB: one bridge, one translation unit per operation.
    let mut vdb = cxx_build::bridge("src/ffi/vdb.rs");
    flags(&mut vdb);
    vdb.files(VDB_UNITS);

    // CGAL: one bridge; the checks here, the repair steps below with settings of their own.
    let mut cgal = cxx_build::bridge("src/ffi/cgal.rs");
    flags(&mut cgal);
    cgal.define("CGAL_LINKED_WITH_TBB", None)
        .file(CGAL_CHECK_UNIT);

    // CGAL's own precondition checks are compiled out here: in the self-intersection search they
    // cost over a quarter of its CPU time (a whole-mesh triangle test on every call, degeneracy
    // tests on every triangle and segment compared), and this code meets them by construction
    // (triangles with three distinct vertices, hole edges checked to be border edges).
    // No bridge of its own: the same CGAL bridge's generated header, on cxx's include path.
    let mut cgal_repair = cxx_build::bridges(std::iter::empty::<&str>());
    flags(&mut cgal_repair);
    cgal_repair
        .define("CGAL_LINKED_WITH_TBB", None)
        .define("CGAL_EIGEN3_ENABLED", None)
        .define("CGAL_NDEBUG", None)
        .file(CGAL_REPAIR_UNIT);

    // Corefinement (booleans), with CGAL's checks on: its inputs are checked here at run time
    // and a failed check is a reason to fall back, not a crash.
    let mut cgal_boolean = cxx_build::bridges(std::iter::empty::<&str>());
    flags(&mut cgal_boolean);
    cgal_boolean
        // GCC 12 warns of CGAL's lazy-kernel functors "maybe uninitialized" in its
        // self-intersection callbacks, hundreds of lines per build: noise, not a finding.
        .flag_if_supported("-Wno-maybe-uninitialized")
        .define("CGAL_LINKED_WITH_TBB", None)
        .file(CGAL_BOOLEAN_UNIT);
    let mut cgal_distance = cxx_build::bridges(std::iter::empty::<&str>());
    flags(&mut cgal_distance);
    cgal_distance
        .define("CGAL_LINKED_WITH_TBB", None)
        .file(CGAL_DISTANCE_UNIT);
    let mut cgal_voronoi = cxx_build::bridges(std::iter::empty::<&str>());
    flags(&mut cgal_voronoi);
    cgal_voronoi.file(CGAL_VORONOI_UNIT);

    // The libraries compile side by side (and, with cc's `parallel`, the units of each): the
    // CGAL units take most of the build, and one at a time they leave the other cores idle.
    let libs = [
        (vdb, "latvox_vdb"),
        (cgal, "latvox_cgal"),
        (cgal_repair, "latvox_cgal_repair"),
        (cgal_boolean, "latvox_cgal_boolean"),
        (cgal_distance, "latvox_cgal_distance"),
        (cgal_voronoi, "latvox_cgal_voronoi"),
    ];
    std::thread::scope(|s| {
        for (build, name) in &libs {
            s.spawn(move || build.clone().cargo_metadata(false).compile(name));
        }
    });
    // Linked in this order (a bridge before the units it calls), whichever finished first.
    println!(
        "cargo:rustc-link-search=native={}",
        std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")
    );
    for (_, name) in &libs {
        println!("cargo:rustc-link-lib=static={name}");
    }
    println!("cargo:rustc-link-lib=stdc++");

    for lib in ["openvdb", "tbb", "Imath-3_1", "gmp", "mpfr"] {
        println!("cargo:rustc-link-lib={lib}");
    }
    for f in ["src/ffi/vdb.rs", "src/ffi/cgal.rs"]
        .into_iter()
        .chain(HEADERS)
        .chain(VDB_UNITS)
        .chain([
            CGAL_CHECK_UNIT,
            CGAL_REPAIR_UNIT,
            CGAL_BOOLEAN_UNIT,
            CGAL_DISTANCE_UNIT,
            CGAL_VORONOI_UNIT,
        ])
    {
        println!("cargo:rerun-if-changed={f}");
    }
}
