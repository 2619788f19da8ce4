#!/usr/bin/env bash
# End-to-end timings of the hexbite commands on this machine, one at a time (two benchmark processes
# at once slow each other down). Prints a Markdown table for docs/performance.md.
# Usage: bench/run_end_to_end.sh [BUILD_DIR] [REPEATS]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
repeats=${2:-3}
hexbite="$build/app/hexbite"
jaw=../shared/data/jaw/jaw_smooth.stl
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# best_of CMD...: the best wall time of $repeats runs, in seconds.
best_of() {
  local best=""
  for _ in $(seq "$repeats"); do
    local t0 t1
    t0=$(date +%s.%N)
    "$@" >/dev/null 2>&1 || { echo "failed: $*" >&2; return 1; }
    t1=$(date +%s.%N)
    best=$(echo "$t0 $t1 $best" | awk '{d = $2 - $1; if ($3 == "" || d < $3) print d; else print $3}')
  done
  printf '%.2f' "$best"
}

echo "Machine: $(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GB", $2 / 1048576}' /proc/meminfo), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'); date: $(date -u +%Y-%m-%d)"
echo
echo "| step | input | best of $repeats (s) |"
echo "| --- | --- | --- |"
echo "| generate mandible | defaults, 1 mm voxels | $(best_of "$hexbite" -q generate mandible -o "$work/jaw.stl" --landmarks "$work/jaw.yaml") |"
echo "| surface check | built-in mandible | $(best_of "$hexbite" -q surface check "$work/jaw.stl") |"
echo "| surface check | real jaw (41,760 triangles) | $(best_of "$hexbite" -q surface check "$jaw") |"
echo "| surface clean | built-in mandible | $(best_of "$hexbite" -q surface clean "$work/jaw.stl" -o "$work/clean1.stl") |"
echo "| surface clean | real jaw | $(best_of "$hexbite" -q surface clean "$jaw" -o "$work/clean2.stl") |"
