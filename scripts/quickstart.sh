#!/usr/bin/env bash
# The README's first command: install what is missing, build, and run the main job on the embedded
# default case.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh --run-only
# The msfem command alone, without image meshing and surface repair (MSFEM_IMAGING, a third of its
# compile time; the default run uses neither): those, the tests, benchmarks and fuzz targets are
# the second command's.
MSFEM_TARGET=msfem bash scripts/build.sh -DMSFEM_IMAGING=OFF
# Two MPI ranks where there are two cores (docs/scale-out.md): the FEM and its error estimate, most
# of the run, share the cores, the variants' steps/s are timed one rank at a time, and the numbers
# are one rank's to the solver's tolerance. A machine where two ranks cannot start (a container
# without shared memory) runs one process.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
if [ "$(nproc)" -ge 2 ] && command -v mpirun >/dev/null &&
  mpirun -np 2 --bind-to none true >/dev/null 2>&1; then
  mpirun -np 2 --bind-to none ./build/compare/msfem run cases/sphere_indent.prm
else
  ./build/compare/msfem run cases/sphere_indent.prm
fi
