#!/usr/bin/env bash
# Configures (once) and builds msfem in build/ with two jobs. Extra arguments go to cmake's configure;
# MSFEM_TARGET=NAME builds that target (and what it needs) only.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${MSFEM_BUILD_DIR:-build}
jobs=${MSFEM_JOBS:-2}
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
if [ ! -f "$build_dir/CMakeCache.txt" ]; then
  cmake -S . -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release "$@"
elif [ $# -gt 0 ]; then
  cmake -S . -B "$build_dir" "$@"
fi
cmake --build "$build_dir" -j "$jobs" ${MSFEM_TARGET:+--target "$MSFEM_TARGET"}
