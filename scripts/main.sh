#!/usr/bin/env bash
# One command for the main job: installs the packages, builds, and runs the default job, the seed paper's
# lateral bite on a hard nut (scenarios/lateral_bite_hard_nut.yaml) on the built-in procedural mandible,
# printing its summary table, and writes its validation report (one HTML file with the pictures inside).
# Outputs go to out/ (or the folder given as the first argument).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
out=${1:-out}
mkdir -p "$out"
hexbite=${HEXBITE_BUILD_DIR:-build}/app/hexbite
"$hexbite" generate mandible -o "$out/jaw.stl" --landmarks "$out/jaw.landmarks.yaml" --ct "$out/jaw.mha"
"$hexbite" surface check "$out/jaw.stl"
"$hexbite" surface clean "$out/jaw.stl" -o "$out/jaw_clean.stl"
"$hexbite" run scenarios/lateral_bite_hard_nut.yaml -o "$out/lateral_bite_hard_nut"
# The report's pictures need an X display; xvfb-run (installed by the set-up) gives one on a headless machine.
runner=()
if [ -z "${DISPLAY:-}" ] && command -v xvfb-run >/dev/null; then runner=(xvfb-run -a); fi
"${runner[@]}" "$hexbite" report "$out/lateral_bite_hard_nut" -o "$out/lateral_bite_hard_nut_report.html"
echo "main: outputs in $out/"
