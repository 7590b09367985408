#!/usr/bin/env bash
# Installs the Debian packages latvox builds against and the tools its tests check with.
# Idempotent: packages already present are not fetched again. Works as root, or through sudo.
set -euo pipefail

PKGS=(
  # build: the C++ libraries behind the bridge
  g++ pkg-config libopenvdb-dev libcgal-dev libtbb-dev libgmp-dev libmpfr-dev libeigen3-dev
  libimath-dev libblosc-dev zlib1g-dev libboost-dev
  # tests: independent checkers
  admesh libopenvdb-tools
  # fgm tests: OpenVDB's own Python module reads the .vdb grids back
  python3-openvdb
  # tests (topo): Python for the published optimisers' reference transcriptions, and the
  # libraries the PyPI gmsh wheel (OpenCASCADE, reads IGES back) links against
  python3 python3-pip python3-venv libglu1-mesa libgl1 libopengl0 libxrender1 libxcursor1
  libxfixes3 libxext6 libxft2 libfontconfig1 libxinerama1 libx11-6 libgomp1
  # tests: a one-node Slurm cluster for latvox batch (scripts/slurm-test.sh)
  slurm-wlm munge
  # mesh check/repair tests: CGAL's data archive of broken meshes; pip for trimesh
  libcgal-demo python3-pip
  # browser editor tests (latvox view): headless Chromium, driven through Playwright
  chromium
)

if [ "$(id -u)" -eq 0 ]; then SUDO=(); else SUDO=(sudo); fi

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
  echo "install-deps: all packages present" >&2
fi

# Python packages for the tests: NumPy/SciPy (reference optimisers, independent checks of the
# cleaned fields), gmsh (OpenCASCADE reads the IGES back), ezdxf (reads the DXF back),
# trimesh with networkx and lxml (an independent mesh analyser for check/repair), shapely
# (checks every slice layer's polygons), Playwright (drives Debian's Chromium through the
# browser editor's page; it uses that browser and downloads none of its own), libigl (the
# peer of the FGM benchmark: its fast winding numbers for point clouds), and manifold3d (cuts a
# graded part at its cells' faces to measure each cell's density).
PY_PKGS=(numpy scipy gmsh ezdxf trimesh networkx lxml lib3mf shapely playwright libigl manifold3d)
PY_IMPORTS="import numpy, scipy, gmsh, ezdxf, trimesh, networkx, lxml, lib3mf, shapely, playwright, igl, manifold3d"
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

# Fuzzing the mesh readers inside `cargo test`: cargo-fuzz on a nightly toolchain.
if command -v rustup >/dev/null 2>&1 && ! rustup toolchain list | grep -q '^nightly'; then
  echo "install-deps: installing the nightly Rust toolchain (for cargo fuzz)" >&2
  rustup toolchain install nightly --profile minimal
fi
if ! command -v cargo-fuzz >/dev/null 2>&1 && [ ! -x "${CARGO_HOME:-$HOME/.cargo}/bin/cargo-fuzz" ]; then
  echo "install-deps: installing cargo-fuzz" >&2
  cargo install --locked cargo-fuzz
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
