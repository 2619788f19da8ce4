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
# A CT as scanners export it: a DICOM series of the built-in mandible at 0.25 mm voxels (318 slices, as fine
# as a dental cone-beam CT), written, read back into a surface (787,644 triangles), and meshed.
echo "| generate mandible --dicom | 0.25 mm voxels, 318 slices | $(best_of "$hexbite" -q generate mandible -o "$work/fine.stl" --voxel 0.25 --dicom "$work/fine_ct") |"
echo "| surface from-ct | that DICOM series | $(best_of "$hexbite" -q surface from-ct "$work/fine_ct" --threshold 620 -o "$work/fine_ct.stl") |"
echo "| mesh --core swept --target-hexes 2500 | that surface | $(best_of "$hexbite" -q mesh "$work/fine_ct.stl" --core swept --target-hexes 2500 -o "$work/fine_ct.vtu") |"
echo "| surface clean | built-in mandible | $(best_of "$hexbite" -q surface clean "$work/jaw.stl" -o "$work/clean1.stl") |"
echo "| surface clean | real jaw | $(best_of "$hexbite" -q surface clean "$jaw" -o "$work/clean2.stl") |"

# Meshing (issues 3 and 4): the grid mesher at the paper's coarse size and at 30,000 hexes (also with the
# grid along the dental arch), the swept core at the coarse size, the sheet mesher with landmarks, and with
# the local refinement around a bite point.
landmarks=../shared/data/jaw/landmarks.yaml
for target in 2500 30000; do
  echo "| mesh --method grid --target-hexes $target | real jaw | $(best_of "$hexbite" -q mesh "$jaw" --method grid --target-hexes "$target" -o "$work/grid.vtu") |"
done
echo "| mesh --core swept --target-hexes 2500 | built-in mandible | $(best_of "$hexbite" -q mesh "$work/jaw.stl" --core swept --target-hexes 2500 -o "$work/swept1.vtu") |"
echo "| mesh --core swept --target-hexes 2500 | real jaw | $(best_of "$hexbite" -q mesh "$jaw" --core swept --target-hexes 2500 -o "$work/swept2.vtu") |"
echo "| mesh --method grid --grid-frame arch --target-hexes 30000 | real jaw | $(best_of "$hexbite" -q mesh "$jaw" --method grid --grid-frame arch --target-hexes 30000 -o "$work/grid_arch.vtu") |"
echo "| mesh --method sheets --landmarks | built-in mandible | $(best_of "$hexbite" -q mesh "$work/jaw.stl" --method sheets --landmarks "$work/jaw.yaml" -o "$work/sheets1.vtu") |"
echo "| mesh --method sheets --landmarks | real jaw | $(best_of "$hexbite" -q mesh "$jaw" --method sheets --landmarks "$landmarks" -o "$work/sheets2.vtu") |"
echo "| mesh --method sheets --landmarks --refine-at right_first_molar_bite_point | real jaw | $(best_of "$hexbite" -q mesh "$jaw" --method sheets --landmarks "$landmarks" --refine-at right_first_molar_bite_point -o "$work/sheets3.vtu") |"

# hexbite run on the default scenario (coarse mesh + 1 validation level), the main job's target: <= 60 s.
scenario=scenarios/lateral_bite_hard_nut.yaml
echo "| run, coarse + 1 validation level | $scenario | $(best_of "$hexbite" -q run "$scenario" -o "$work/run") |"
# Its validation report, without and with its three pictures (these need an X display: xvfb-run gives one).
echo "| report --no-pictures | the run above | $(best_of "$hexbite" -q report "$work/run" -o "$work/report.html" --no-pictures) |"
display=()
if [ -z "${DISPLAY:-}" ] && command -v xvfb-run >/dev/null; then display=(xvfb-run -a); fi
echo "| report (3 pictures) | the run above | $(best_of "${display[@]}" "$hexbite" -q report "$work/run" -o "$work/report.html") |"
# The shipped what-if study: four variants of the default scenario, each coarse + 1 validation level.
echo "| study, 4 variants | scenarios/studies/atrophy_what_if.yaml | $(best_of "$hexbite" -q study scenarios/studies/atrophy_what_if.yaml -o "$work/study") |"

# ccx_time DIR [SOLVER]: wall seconds of CalculiX on DIR/model.inp, with its default solver (SPOOLES) or
# with *STATIC, SOLVER=ITERATIVE CHOLESKY, the two solvers Debian's CalculiX has.
ccx_time() {
  local dir=$1 solver=${2:-}
  if [ -n "$solver" ]; then
    sed -i "s/^\*STATIC.*/*STATIC, SOLVER=$solver/" "$dir/model.inp"
  fi
  (cd "$dir" && best_of ccx -i model)
}

# The same model side by side with CalculiX (Q1 / C3D8, same mesh, same nodal loads and supports): the
# coarse mesh of the default scenario, and a fine one near 200,000 degrees of freedom (issue 5's target).
# Our figure is the solver's own time (solver.seconds in results.json: set-up, assembly, AMG, CG, stresses);
# CalculiX's is its wall time, which also includes reading the deck.
for target in 4000 60000; do
  dir="$work/ccx_$target"
  sed -e "s/target_hexes: [0-9]*/target_hexes: $target/" "$scenario" >"$work/side_by_side.yaml"
  sed -i "s/linear_solver: auto/linear_solver: cg_amg/" "$work/side_by_side.yaml"
  "$hexbite" -q run "$work/side_by_side.yaml" -o "$dir" --levels 0 --export inp
  dofs=$(python3 -c "import json; print(json.load(open('$dir/results.json'))['mesh']['dofs'])")
  ours=$(python3 -c "import json; print('%.2f' % json.load(open('$dir/results.json'))['solver']['seconds'])")
  echo "| hexbite solve (CG + AMG) | target $target hexes, $dofs DoFs | $ours |"
  echo "| ccx SPOOLES | same model.inp | $(ccx_time "$dir") |"
  echo "| ccx iterative Cholesky | same model.inp | $(ccx_time "$dir" "ITERATIVE CHOLESKY") |"
done
