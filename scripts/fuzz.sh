#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz) with clang, seeds each corpus from the project's own
# files (cases/data surfaces by format, cases/*.prm; tiny NIfTI images from the tests' writer, plain
# and gzipped) and runs each target for a bounded time:
#   bash scripts/fuzz.sh [SECONDS_PER_TARGET]   (default 60)
# Exits non-zero on the first crash, leak, hang (-timeout) or sanitizer report; the input that
# caused it is left in build-fuzz/ as crash-*, leak-* or timeout-*.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
CC=clang CXX=clang++ cmake -S tests/fuzz -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build-fuzz -j "${MSFEM_JOBS:-2}"
for format in obj stl off ply x3d case nifti vtu vtk xsp; do
  corpus=build-fuzz/corpus/$format
  mkdir -p "$corpus"
  if [ "$format" = case ]; then
    cp cases/*.prm tests/compare/data/*.prm "$corpus"/
  elif [ "$format" = nifti ]; then
    # The cases' scans are megabytes: written seeds of a few hundred bytes mutate faster.
    build-fuzz/nifti_seeds "$corpus" >/dev/null
    for seed in "$corpus"/v1_le_int16.nii "$corpus"/v2_be_float32.nii; do
      gzip -c "$seed" >"$seed.gz"
    done
  elif [ "$format" = vtu ] || [ "$format" = vtk ] || [ "$format" = xsp ]; then
    # A small network in each format, written by msfem's own writer (and by hand for legacy VTK).
    build-fuzz/network_seeds build-fuzz/corpus/networks >/dev/null
    cp build-fuzz/corpus/networks/*."${format/xsp/xs3}" "$corpus"/
  elif [ "$format" = x3d ]; then
    # A small scene in msfem's own X3D: the icosphere as write_surface writes it.
    printf '%s\n' '<?xml version="1.0"?><X3D version="3.3"><Scene><Shape DEF="s">' \
      '<IndexedFaceSet coordIndex="0 1 2 -1 0 2 3 -1 0 3 1 -1 1 3 2 -1">' \
      '<Coordinate point="0 0 0, 0.01 0 0, 0 0.01 0, 0 0 0.01"/></IndexedFaceSet></Shape>' \
      '</Scene></X3D>' >"$corpus/tetrahedron.x3d"
  else
    # Small seeds only: libFuzzer mutates them, and -max_len caps what it grows them to.
    find cases/data tests -name "*.$format" -size -200k -exec cp {} "$corpus"/ \; 2>/dev/null || true
  fi
  echo "== fuzz_$format: ${seconds} s"
  (cd build-fuzz && ./fuzz_$format -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
     -max_len=65536 -print_final_stats=1 "corpus/$format" 2>&1 | grep -E "^(#[0-9]+ *DONE|stat::number_of_executed_units|==[0-9]+==ERROR|SUMMARY)" || true)
  if ls build-fuzz/crash-* build-fuzz/leak-* build-fuzz/timeout-* >/dev/null 2>&1; then
    echo "fuzz_$format found a defect: $(ls build-fuzz/crash-* build-fuzz/leak-* build-fuzz/timeout-* 2>/dev/null)" >&2
    exit 1
  fi
done
