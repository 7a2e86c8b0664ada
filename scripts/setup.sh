#!/usr/bin/env bash
# Installs ofv's dependencies (Debian 12 packages), then configures and builds
# ofv into build/ (Release). Extra arguments go to the CMake configure step,
# e.g. scripts/setup.sh -DOFV_BUILD_BENCH=OFF. OFV_BUILD_DIR picks another
# build directory; OFV_JOBS the parallel jobs (default 2).
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install-deps.sh
build_dir=${OFV_BUILD_DIR:-build}
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE="${OFV_BUILD_TYPE:-Release}" "$@"
cmake --build "$build_dir" -j "${OFV_JOBS:-2}"
