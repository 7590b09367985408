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
  # tests: a one-node Slurm cluster for latvox batch (scripts/slurm-test.sh)
  slurm-wlm munge
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
