#!/usr/bin/env bash
# Installs the Debian 12 packages msfem needs; skips what is present, runs `apt-get update` at most once.
#   bash scripts/install-deps.sh [--run-only]   (--run-only: not the test suite's own tools)
set -euo pipefail

packages=(
  build-essential cmake ninja-build git pkg-config
  libeigen3-dev          # massspring's only dependency: dense/sparse linear algebra
  libnanoflann-dev       # k-d tree for the skeleton's 4-nearest control points (header-only)
  libdeal.ii-dev         # FEM reference; brings PETSc (hypre, MUMPS), MPI, HDF5, Gmsh, CGAL, p4est
  libcgal-dev            # surface validation (self-intersections), simplification, Mesh_3 extraction
  libnifti2-dev          # msfem surface-from-image: NIfTI-1/2 reader (niftilib, the reference implementation)
  openmpi-bin            # mpirun: the quick start's two ranks, msfem under MPI (docs/scale-out.md)
  libhdf5-openmpi-dev    # fields.h5 output (the HDF5 deal.II links, so one HDF5 per process)
  nlohmann-json3-dev     # summary.json and every --json output
  libpugixml-dev         # user networks as VTK XML (.vtu): a small DOM reader; zlib (deal.II's) inflates
  libnlopt-cxx-dev       # msfem calibrate: derivative-free optimiser (BOBYQA) for spring coefficients
  libsuitesparse-dev     # CHOLMOD: spring statics in msfem run/sweep/calibrate
  libopenblas0-serial    # optimised BLAS under CHOLMOD's supernodal kernels (reference BLAS is 2x slower)
  libgtest-dev           # unit and end-to-end tests
  libbenchmark-dev       # speed measurements
  gnuplot-nox            # plots in report.md
)
# What only the test suite and CI use; `--run-only` (the README's first command) leaves them out.
test_packages=(
  python3                # CI's check of the embedding example reads summary.json
  clang libclang-rt-14-dev  # libFuzzer (clang's) for the reader fuzz targets CI runs (scripts/fuzz.sh)
  libxml2-utils          # xmllint: the tests check each run's scene.x3d is well-formed XML
)
# Headless Chromium draws scene.html (X3DOM) for its test; a machine that cannot install it skips
# that test and says why, so it is tried on its own and never stops the rest.
optional_test_packages=(chromium)
[ "${1:-}" = "--run-only" ] || packages+=("${test_packages[@]}")

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

optional_missing=()
if [ "${1:-}" != "--run-only" ]; then
  for p in "${optional_test_packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" ||
      optional_missing+=("$p")
  done
fi

if [ ${#missing[@]} -eq 0 ] && [ ${#optional_missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -q
if [ ${#missing[@]} -gt 0 ]; then
  echo "install-deps: installing ${missing[*]}"
  "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
if [ ${#optional_missing[@]} -gt 0 ]; then
  echo "install-deps: installing ${optional_missing[*]} (optional: the scene.html test)"
  "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${optional_missing[@]}" ||
    echo "install-deps: ${optional_missing[*]} could not be installed; the scene.html test is skipped"
fi
