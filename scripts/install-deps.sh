#!/usr/bin/env bash
# Installs what latvox needs, in two tiers:
#
#   scripts/install-deps.sh          building and running latvox: the compiler and the
#                                    development packages of OpenVDB, CGAL and what they link
#   scripts/install-deps.sh --tests  that, and what the tests check with: independent checkers
#                                    (admesh, OpenVDB's tools and Python module, trimesh,
#                                    manifold3d, lib3mf, shapely, gmsh, ezdxf, SciPy, libigl),
#                                    CGAL's and the slicers' meshes, headless Chromium with
#                                    Playwright, a one-node Slurm cluster (slurm-wlm, munge), the
#                                    nightly toolchain with cargo-fuzz, and mdBook for the book
#
# Debian bookworm. Idempotent: what is present is not fetched again. Works as root, or through
# sudo.
set -euo pipefail

TESTS=0
for arg in "$@"; do
  case "$arg" in
    --tests) TESTS=1 ;;
    -h | --help)
      sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'
      exit 0
      ;;
    *)
      echo "install-deps: unknown option '$arg' (--tests adds the test tier)" >&2
      exit 2
      ;;
  esac
done

if [ "$(id -u)" -eq 0 ]; then SUDO=(); else SUDO=(sudo); fi

# Building and running: the C++ libraries behind the bridge.
PKGS=(
  g++ pkg-config libopenvdb-dev libcgal-dev libtbb-dev libgmp-dev libmpfr-dev libeigen3-dev
  libimath-dev libblosc-dev zlib1g-dev libboost-dev
)
if [ "$TESTS" -eq 1 ]; then
  PKGS+=(
    # independent checkers; GNU time reads a child's peak memory from the kernel
    admesh libopenvdb-tools time
    # fgm tests: OpenVDB's own Python module reads the .vdb grids back
    python3-openvdb
    # Python for the reference optimisers and checkers, and the libraries the PyPI gmsh wheel
    # (OpenCASCADE, reads IGES back) links against
    python3 python3-pip python3-venv libglu1-mesa libgl1 libopengl0 libxrender1 libxcursor1
    libxfixes3 libxext6 libxft2 libfontconfig1 libxinerama1 libx11-6 libgomp1
    # batch tests: a one-node Slurm cluster (scripts/slurm-test.sh)
    slurm-wlm munge
    # check/repair tests: CGAL's data archive of broken meshes
    libcgal-demo
    # browser editor tests (latvox view): headless Chromium, driven through Playwright
    chromium
  )
fi

missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -gt 0 ]; then
  echo "install-deps: installing ${missing[*]}" >&2
  export DEBIAN_FRONTEND=noninteractive
  "${SUDO[@]}" apt-get update -qq
  "${SUDO[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
else
  echo "install-deps: Debian packages present" >&2
fi

[ "$TESTS" -eq 1 ] || exit 0

# Python packages for the tests: NumPy/SciPy (reference optimisers, independent checks of the
# cleaned fields), gmsh (OpenCASCADE reads the IGES back), ezdxf (reads the DXF back),
# trimesh with networkx and lxml (an independent mesh analyser for check/repair), lib3mf (reads
# 3MF back), shapely (checks every slice layer's polygons), Playwright (drives Debian's Chromium
# through the browser editor's page; it uses that browser and downloads none of its own), libigl
# (the peer of the FGM benchmark: its fast winding numbers for point clouds), and manifold3d
# (cuts a graded part at its cells' faces to measure each cell's density); maturin, pytest and
# tqdm build and test the Python package (python/); fast-simplification (the mesh-only
# decimator beside `--tolerance` in its benchmark).
PY_PKGS=(numpy scipy gmsh ezdxf trimesh networkx lxml lib3mf shapely playwright libigl manifold3d maturin pytest tqdm fast-simplification)
PY_IMPORTS="import numpy, scipy, gmsh, ezdxf, trimesh, networkx, lxml, lib3mf, shapely, playwright, igl, manifold3d, maturin, pytest, tqdm, fast_simplification"
if python3 -c "$PY_IMPORTS" 2>/dev/null; then
  echo "install-deps: Python packages present" >&2
else
  echo "install-deps: installing Python packages ${PY_PKGS[*]}" >&2
  pip_install() { python3 -m pip install --quiet --disable-pip-version-check "$@" "${PY_PKGS[@]}"; }
  if [ "$(id -u)" -eq 0 ] || [ -w "$(python3 -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')" ]; then
    pip_install 2>/dev/null || pip_install --break-system-packages
  else
    pip_install --user 2>/dev/null || pip_install --user --break-system-packages
  fi
  python3 -c "$PY_IMPORTS"
fi

CARGO_BIN="${CARGO_HOME:-$HOME/.cargo}/bin"

# The fuzz campaign of the long tier: cargo-fuzz on a nightly toolchain.
if command -v rustup >/dev/null 2>&1 && ! rustup toolchain list | grep -q '^nightly'; then
  echo "install-deps: installing the nightly Rust toolchain (for cargo fuzz)" >&2
  rustup toolchain install nightly --profile minimal
fi
if ! command -v cargo-fuzz >/dev/null 2>&1 && [ ! -x "$CARGO_BIN/cargo-fuzz" ]; then
  echo "install-deps: installing cargo-fuzz" >&2
  cargo install --locked cargo-fuzz
fi

# The book (docs/): mdBook, without its live-reload server.
if ! command -v mdbook >/dev/null 2>&1 && [ ! -x "$CARGO_BIN/mdbook" ]; then
  echo "install-deps: installing mdbook" >&2
  cargo install --locked mdbook --no-default-features --features search
fi

# check/repair tests: real meshes shipped with Debian's slicers (printer beds, platforms, test
# shapes from Cura and PrusaSlicer), taken out of the packages without installing them (nor
# their GUI dependencies).
CORPUS=/usr/local/share/latvox/slicer-meshes
if [ ! -f "$CORPUS/.complete" ]; then
  echo "install-deps: unpacking the meshes of Debian's cura and prusa-slicer packages" >&2
  tmp=$(mktemp -d)
  (cd "$tmp" && { apt-get download cura prusa-slicer >/dev/null 2>&1 ||
    { "${SUDO[@]}" apt-get update -qq && apt-get download cura prusa-slicer >/dev/null; }; })
  for pkg in cura prusa-slicer; do
    dpkg-deb -x "$tmp"/"${pkg}"_*.deb "$tmp/$pkg"
    "${SUDO[@]}" mkdir -p "$CORPUS/$pkg"
    find "$tmp/$pkg" -type f \( -iname '*.stl' -o -iname '*.3mf' -o -iname '*.obj' \) \
      -size -3M -exec "${SUDO[@]}" cp -t "$CORPUS/$pkg" {} +
  done
  "${SUDO[@]}" touch "$CORPUS/.complete"
  rm -rf "$tmp"
fi
