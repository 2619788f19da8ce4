#!/usr/bin/env bash
# Configures and builds hexbite (Release) into build/; the set-up script must have run first.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${HEXBITE_BUILD_DIR:-build}
jobs=${HEXBITE_JOBS:-2}
if [ ! -f "$build_dir/build.ninja" ]; then
  cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release
fi
cmake --build "$build_dir" -j "$jobs"
