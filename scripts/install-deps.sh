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
  # mesh check/repair tests: CGAL's data archive of broken meshes; pip for trimesh
  libcgal-demo python3-pip
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

# Mesh check/repair tests: trimesh (PyPI) as an independent mesh analyser.
if ! python3 -c "import trimesh, networkx, lxml" 2>/dev/null; then
  echo "install-deps: installing trimesh (PyPI)" >&2
  python3 -m pip install --quiet --disable-pip-version-check trimesh networkx lxml numpy \
    || python3 -m pip install --quiet --disable-pip-version-check --break-system-packages trimesh networkx lxml numpy
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
