#!/usr/bin/env bash
# One command for everything: installs the packages, builds, and runs all tests with CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
build_dir=${HEXBITE_BUILD_DIR:-build}
# Rendering tests need an X display; xvfb-run provides one on headless machines and CI.
runner=()
if [ -z "${DISPLAY:-}" ] && command -v xvfb-run >/dev/null; then runner=(xvfb-run -a); fi
"${runner[@]}" ctest --test-dir "$build_dir" --output-on-failure -j 2 "$@"
