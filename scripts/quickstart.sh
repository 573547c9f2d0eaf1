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
./build/compare/msfem run cases/sphere_indent.prm
