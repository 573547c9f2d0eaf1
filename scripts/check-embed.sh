#!/usr/bin/env bash
# The massspring package as a simulator uses it: installs build/ to a prefix, builds
# examples/embed out of tree against it (CMake package, then pkg-config), checks that no deal.II,
# PETSc or MPI path reached the example's compile lines, and runs it against `msfem run`'s own
# three_tier force on the seed sphere. Needs the main build (scripts/build.sh) first.
set -euo pipefail
cd "$(dirname "$0")/.."
prefix=$PWD/build-install
rm -rf "$prefix" build-embed
cmake --install build --prefix "$prefix" >/dev/null
cmake -S examples/embed -B build-embed -G Ninja -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build build-embed -j "${MSFEM_JOBS:-2}"
if grep -qi "deal.II\|petsc\|/mpi" build-embed/compile_commands.json; then
  echo "check-embed: the example's compile lines refer to deal.II, PETSc or MPI" >&2
  exit 1
fi
pc_dir=$(dirname "$(find "$prefix" -name msfem_massspring.pc)")
# shellcheck disable=SC2046
c++ -O2 examples/embed/simulator.cpp -o build-embed/embed_simulator_pkgconfig \
  $(PKG_CONFIG_PATH="$pc_dir" pkg-config --cflags --libs msfem_massspring)
./build/compare/msfem run cases/sphere_indent.prm --quiet --no-timing --no-curve --no-cache \
  --set fem/degree=1 --set "fem/error estimate=none" --set "mass spring/variants=three_tier" \
  --out build-embed/run
force=$(python3 -c 'import json,sys; print(repr(json.load(open(sys.argv[1]))["variants"][0]["reaction_force_N"][2]))' \
  build-embed/run/summary.json)
for program in embed_simulator embed_simulator_pkgconfig; do
  echo "== $program"
  build-embed/$program --expect-force "$force"
done
