#!/usr/bin/env bash
# Measures the figures that docs/validation.md, docs/running.md, docs/scenario-format.md, README.md and
# docs/performance.md quote for the shipped scenarios, so that they can be re-measured in a few minutes after
# a change of the mesher or the solver:
#   1. `hexbite run` of the three shipped scenarios (scenarios/*.yaml, validation_levels as shipped);
#   2. the default scenario mirrored to a left bite (the nut on the left first molar, the activation
#      pattern's sides swapped, as tests/test_run.cc `mirrored()` does) at --levels 0, against the right bite;
#   3. the incisal bite at --levels 0 --export inp, solved again by CalculiX (`ccx -i model`): largest nodal
#      displacement and support reactions, CalculiX's K u reactions less the muscle loads on the support
#      nodes, because results.json reports K u - f (docs/running.md, "The CalculiX export");
#   4. the default scenario at --levels 0 serially and under `mpirun -np 2` (as the CTest pair
#      run_serial/run_np2 and tests/test_run_mpi.cc): the largest relative difference of the figures;
#   5. the default scenario with `mesh.fit_volume: true` (docs/scenario-format.md, `fit_volume`);
#   6. the steps of scripts/main.sh before the run (generate, surface check, surface clean), timed;
#   7. the default scenario with `mesh.method: sheets` (docs/running.md, "Mesh size").
# Then prints one summary (a Markdown table of every level of the shipped scenarios, then a few lines per
# check) and writes it to OUT_DIR/summary.md; each run's output is in OUT_DIR/<name>.log, its wall time in
# OUT_DIR/<name>.wall. Not here: the 60,000-hex side by side with CalculiX of docs/validation.md (grid core,
# a few minutes; bench/run_end_to_end.sh) and the real jaw (RunRealJaw in tests/test_run.cc).
#
# Usage: scripts/measure_shipped_scenarios.sh BUILD_DIR OUT_DIR
#   BUILD_DIR: a Release build with app/hexbite built (e.g. build); OUT_DIR: created, one folder per run.
# Needs python3 (standard library only), ccx (CalculiX) and mpirun. About 1 minute of hexbite runs on
# an idle 2-core machine; everything runs one at a time (two ranks for step 4).
set -euo pipefail
if [ $# -ne 2 ]; then
  sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//' >&2
  exit 2
fi
build=$(cd "$1" && pwd)
mkdir -p "$2"
out=$(cd "$2" && pwd)
cd "$(dirname "$0")/.."
hexbite="$build/app/hexbite"
[ -x "$hexbite" ] || { echo "no $hexbite: build it first (ninja -C $build hexbite)" >&2; exit 2; }

# Where and when, for the docs' "measured on" sentences.
{
  echo "date: $(date -u '+%Y-%m-%d %H:%M UTC')"
  echo "commit: $(git rev-parse --short HEAD 2>/dev/null || echo unknown)$(git diff --quiet HEAD -- . ':!*.md' ':!scripts' 2>/dev/null || echo ' (with local changes)')"
  echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
  echo "uptime at start: $(uptime)"
} >"$out/env.txt"

# timed NAME CMD...: runs CMD, its output to OUT_DIR/NAME.log, its wall seconds to OUT_DIR/NAME.wall.
timed() {
  local name=$1
  shift
  local t0 t1
  t0=$(date +%s.%N)
  if ! "$@" >"$out/$name.log" 2>&1; then
    echo "failed: $* (see $out/$name.log)" >&2
    exit 1
  fi
  t1=$(date +%s.%N)
  echo "$t0 $t1" | awk '{printf "%.2f\n", $2 - $1}' >"$out/$name.wall"
}

# 6. scripts/main.sh's steps before the run.
timed generate "$hexbite" generate mandible -o "$out/jaw.stl" --landmarks "$out/jaw.landmarks.yaml" --ct "$out/jaw.mha"
timed check "$hexbite" surface check "$out/jaw.stl"
timed clean "$hexbite" surface clean "$out/jaw.stl" -o "$out/jaw_clean.stl"

# 1. The shipped scenarios as shipped.
for s in lateral_bite_hard_nut incisal_bite right_molar_clench; do
  timed "$s" "$hexbite" run "scenarios/$s.yaml" -o "$out/$s"
done

# 2. The mirrored default scenario: {right: a, left: b} -> {right: b, left: a}, the nut on the left molar.
python3 - "$out/left_bite.yaml" <<'EOF'
import re, sys
text = open("scenarios/lateral_bite_hard_nut.yaml").read()
text = re.sub(r"\{right: ([0-9.]+), left: ([0-9.]+)\}", r"{right: \2, left: \1}", text)
text = text.replace("at: right_first_molar_bite_point", "at: left_first_molar_bite_point")
assert "{right: 0.20, left: 0.56}" in text
open(sys.argv[1], "w").write(text)
EOF
timed left_bite "$hexbite" run "$out/left_bite.yaml" -o "$out/left_bite" --levels 0

# 3. CalculiX on the incisal bite's exported coarse model.
timed incisal_ccx "$hexbite" run scenarios/incisal_bite.yaml -o "$out/incisal_ccx" --levels 0 --export inp
(cd "$out/incisal_ccx" && timed ccx ccx -i model)

# 4. Serial against two ranks, the default scenario's coarse level.
timed serial "$hexbite" -q run scenarios/lateral_bite_hard_nut.yaml -o "$out/serial" --levels 0
timed np2 mpirun -np 2 --allow-run-as-root --oversubscribe "$hexbite" -q run \
  scenarios/lateral_bite_hard_nut.yaml -o "$out/np2" --levels 0

# 5. The default scenario with the volume fit.
sed 's/^mesh:$/mesh:\n  fit_volume: true/' scenarios/lateral_bite_hard_nut.yaml >"$out/lateral_fit_volume.yaml"
grep -q "fit_volume: true" "$out/lateral_fit_volume.yaml" || { echo "could not add fit_volume" >&2; exit 1; }
timed lateral_fit_volume "$hexbite" run "$out/lateral_fit_volume.yaml" -o "$out/lateral_fit_volume"

# 7. The default scenario with the sheet mesher (mesh.core is for the grid method only).
sed -e 's/^  method: grid/  method: sheets/' -e '/^  core: /d' scenarios/lateral_bite_hard_nut.yaml >"$out/lateral_sheets.yaml"
grep -q "method: sheets" "$out/lateral_sheets.yaml" || { echo "could not switch to sheets" >&2; exit 1; }
timed lateral_sheets "$hexbite" run "$out/lateral_sheets.yaml" -o "$out/lateral_sheets"

echo "uptime at end: $(uptime)" >>"$out/env.txt"

python3 - "$out" <<'EOF' | tee "$out/summary.md"
import json, math, os, re, sys

out = sys.argv[1]
def load(name): return json.load(open(os.path.join(out, name, "results.json")))
def wall(name): return open(os.path.join(out, name + ".wall")).read().strip()
def norm(v): return math.sqrt(sum(x * x for x in v))

print("".join("    " + line for line in open(os.path.join(out, "env.txt"))))
print("main.sh steps before the run (wall s): generate %s, surface check %s, surface clean %s"
      % (wall("generate"), wall("check"), wall("clean")))
print()

# 1. The shipped scenarios, every level.
print("| scenario | level | core | hexes | DoFs | bite force N | reactions N (supports in order) | max disp mm | vM max / p99 MPa "
      "| strain energy mJ | residual | solver | seconds |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for s in ("lateral_bite_hard_nut", "incisal_bite", "right_molar_clench"):
    r = load(s)
    for lv in r["validation"]["levels"]:
        k = lv["level"]
        solver = ("direct" if lv["solver"]["iterations"] == 0 else "CG %d it" % lv["solver"]["iterations"])
        secs = "mesh %.2f, solve %.2f" % (r["seconds"]["mesh_per_level"][k], r["seconds"]["solve_per_level"][k])
        print("| %s | %d | %s | %d | %d | %.2f | %s | %.4f | %.2f / %.2f | %.3f | %.1e | %s | %s |" % (
            s, k, r["mesh"].get("core", r["mesh_method"]) if k == 0 else "", lv["hexes"], lv["dofs"],
            lv["bite_force_N"], " / ".join("%.2f" % lv["reactions"][p["name"]]["magnitude_N"] for p in r["supports"]),
            lv["max_displacement_mm"], lv["von_mises_max_MPa"], lv["von_mises_p99_MPa"], lv["strain_energy_mJ"],
            lv["equilibrium_residual"], solver, secs))
print()
for s in ("lateral_bite_hard_nut", "incisal_bite", "right_molar_clench"):
    r = load(s)
    c = r["validation"]["relative_change"]
    q, f = r["mesh"]["quality"], r["mesh"]["fidelity"]
    print("%s: change %+.2f %% bite, %+.2f %% max disp, %+.2f %% energy; applied (%s) N, |applied| %.1f N, "
          "summed magnitudes %.1f N; coarse mesh: %d inverted, SJ min %.3f / mean %.3f, kappa max %.2f, "
          "Hausdorff %.2f mm, volume %+.2f %%, %d unresolved; run total %.2f s (wall %s s: geometry %.2f, "
          "meshing %s, solves %s, output %.2f)" % (
              s, 100 * c["bite_force"], 100 * c["max_displacement"], 100 * c["strain_energy"],
              ", ".join("%.1f" % x for x in r["applied_force_N"]), norm(r["applied_force_N"]),
              sum(m["magnitude_N"] for m in r["muscles"]), q["inverted"], q["scaled_jacobian"]["min"],
              q["scaled_jacobian"]["mean"], q["condition"]["max"], f["hausdorff_mm"],
              100 * f["volume_difference"], len(f["unresolved"]), r["seconds"]["total"], wall(s),
              r["seconds"]["geometry"], " + ".join("%.2f" % x for x in r["seconds"]["mesh_per_level"]),
              " + ".join("%.2f" % x for x in r["seconds"]["solve_per_level"]), r["seconds"]["output"]))
    for name in (p["name"] for p in r["supports"]):
        v = r["reactions"][name]
        print("    %s reaction (%s) N" % (name, ", ".join("%.1f" % x for x in v["force_N"])))
    print("    unresolved: " + "; ".join("%.2f mm near %s" % (u["extent_mm"], ", ".join(n["name"] for n in u.get("near", [])) or "?")
                                          for u in f["unresolved"]))
print()

# 2. Mirror symmetry: left bite (level 0) against the right bite's level 0.
right = load("lateral_bite_hard_nut")["validation"]["levels"][0]
left = load("left_bite")
mirror = {"nut": "nut", "right_condyle": "left_condyle", "left_condyle": "right_condyle"}
worst = 0.0
for a, b in mirror.items():
    fa, fb = right["reactions"][a]["force_N"], left["reactions"][b]["force_N"]
    worst = max(worst, abs(fa[0] + fb[0]), abs(fa[1] - fb[1]), abs(fa[2] - fb[2]))
print("mirror: left bite %.2f N (%d hexes) against right %.2f N (%d hexes): %.3f %%; reaction components "
      "mirrored within %.3f N (%.3f %% of the bite force); left bite core %s" % (
          left["bite_force_N"], left["mesh"]["hexes"], right["bite_force_N"], right["hexes"],
          100 * abs(left["bite_force_N"] - right["bite_force_N"]) / right["bite_force_N"], worst,
          100 * worst / right["bite_force_N"], left["mesh"].get("core")))

# The mesh's own symmetry, from the incisal bite's export (the same built-in mandible and mesh settings as
# the default scenario, so the same mesh): nodes on either side, and how far a node's mirror image lies from
# the nearest node (buckets of 2 mm).
d = os.path.join(out, "incisal_ccx")
nodes = []
for line in open(os.path.join(d, "model_mesh.inp")):
    if line.startswith("*ELEMENT"): break
    if line[:1].isdigit(): nodes.append(tuple(float(x) for x in line.split(",")[1:4]))
buckets = {}
for p in nodes: buckets.setdefault(tuple(int(math.floor(c / 2)) for c in p), []).append(p)
gaps = []
for p in nodes:
    q = (-p[0], p[1], p[2])
    k = tuple(int(math.floor(c / 2)) for c in q)
    gaps.append(min([math.dist(q, n) for i in (-1, 0, 1) for j in (-1, 0, 1) for l in (-1, 0, 1)
                     for n in buckets.get((k[0] + i, k[1] + j, k[2] + l), [])] or [float("inf")]))
gaps.sort()
print("    mesh symmetry: %d nodes, %d at x > 0 (left), %d at x < 0; a node's mirror image lies a median %.2f mm, "
      "at most %.2f mm from the nearest node" % (len(nodes), sum(p[0] > 0 for p in nodes),
                                                  sum(p[0] < 0 for p in nodes), gaps[len(gaps) // 2], gaps[-1]))

# 3. CalculiX on the incisal bite's exported model.
r = load("incisal_ccx")
u, totals, section = {}, {}, None
for line in open(os.path.join(d, "model.dat")):
    m = re.search(r"^ (displacements|total force) .* for set (\S+) and time", line)
    if m:
        section, cur = m.group(1), m.group(2)
        continue
    f = line.split()
    try:
        if section == "displacements" and len(f) == 4: u[int(f[0])] = [float(x) for x in f[1:]]
        elif section == "total force" and len(f) == 3: totals[cur] = [float(x) for x in f]
    except ValueError:
        pass
sets, cur = {}, None
for line in open(os.path.join(d, "model_mesh.inp")):
    m = re.match(r"^\*NSET, NSET=(\S+)", line)
    if m:
        cur = m.group(1); sets[cur] = []; continue
    if line.startswith("*"):
        cur = None; continue
    if cur: sets[cur] += [int(x) for x in line.replace(",", " ").split()]
loads, cload = {}, False
for line in open(os.path.join(d, "model.inp")):
    if line.startswith("*"):
        cload = line.strip() == "*CLOAD" or (cload and line.startswith("**")); continue
    if cload:
        f = line.replace(",", " ").split()
        if len(f) == 3: loads.setdefault(int(f[0]), [0.0] * 3)[int(f[1]) - 1] += float(f[2])
elements, section = 0, None
for line in open(os.path.join(d, "model_mesh.inp")):
    if line.startswith("*"): section = line.split(",")[0].strip().upper(); continue
    if section == "*ELEMENT" and line.strip(): elements += 1
ccx_max = max(norm(v) for v in u.values())
ours_max = r["max_displacement_mm"]
print("CalculiX (incisal bite, level 0, %d nodes, %d elements, core %s, ccx %s s wall): largest nodal displacement "
      "%.7f mm against ours %.7f mm (relative %.1e)" % (len(u), elements, r["mesh"].get("core"), wall("ccx"),
                                                     ccx_max, ours_max, abs(ccx_max - ours_max) / ours_max))
worst_rel = 0.0
for name, v in r["reactions"].items():
    s = "SUP_" + name.upper()
    expected = list(totals[s])
    for node in sets[s]:
        for c in range(3): expected[c] -= loads.get(node, [0.0] * 3)[c]
    rel = max(abs(a - b) for a, b in zip(v["force_N"], expected)) / v["magnitude_N"]
    worst_rel = max(worst_rel, rel)
    print("    %s: ours (%s) N, CalculiX less the loads on its nodes (%s) N, %.1e of the magnitude" % (
        name, ", ".join("%.3f" % x for x in v["force_N"]), ", ".join("%.3f" % x for x in expected), rel))
print("    reactions agree to %.1e of their magnitude; equilibrium residual %.1e" % (worst_rel, r["equilibrium_residual"]))

# 4. Serial against two ranks.
s1, s2 = load("serial"), load("np2")
def rel_diff(a, b):
    if isinstance(a, (int, float)) and not isinstance(a, bool):
        m = max(abs(a), abs(b))
        return abs(a - b) / m if m else 0.0
    if isinstance(a, list): return max(rel_diff(x, y) for x, y in zip(a, b))
    if isinstance(a, dict): return max([rel_diff(a[k], b[k]) for k in a] or [0.0])
    return 0.0
worst = 0.0
for key in ("bite_force_N", "applied_force_N", "max_displacement_mm", "max_displacement_at", "von_mises_max_MPa",
            "von_mises_p99_MPa", "strain_energy_mJ"):
    worst = max(worst, rel_diff(s1[key], s2[key]))
for name in s1["reactions"]: worst = max(worst, rel_diff(s1["reactions"][name]["force_N"], s2["reactions"][name]["force_N"]))
for name in s1["probes"]: worst = max(worst, rel_diff(s1["probes"][name]["displacement_mm"], s2["probes"][name]["displacement_mm"]))
cells = 0
for piece in os.listdir(os.path.join(out, "np2")):
    if re.match(r"solution_\d+\.vtu$", piece):
        with open(os.path.join(out, "np2", piece), "rb") as fh:
            m = re.search(rb'NumberOfCells="(\d+)"', fh.read(4096))
            cells += int(m.group(1))
print("serial vs mpirun -np 2 (default scenario, level 0): figures agree to %.1e relative; ranks %d / %d; "
      "solution.pvtu pieces hold %d hexes (serial %d); residual %.1e / %.1e; wall %s / %s s" % (
          worst, s1["solver"]["ranks"], s2["solver"]["ranks"], cells, s1["mesh"]["hexes"],
          s1["equilibrium_residual"], s2["equilibrium_residual"], wall("serial"), wall("np2")))

# 5. The volume fit.
a, b = load("lateral_bite_hard_nut"), load("lateral_fit_volume")
fit_line = [l.strip() for l in open(os.path.join(out, "lateral_fit_volume.log")) if "fit_volume" in l]
print("fit_volume: %s" % (fit_line[0] if fit_line else "(no fit_volume line printed)"))
la, lb = a["validation"]["levels"], b["validation"]["levels"]
def pair(key, fmt): return " / ".join(fmt % l[key] for l in lb) + " against " + " / ".join(fmt % l[key] for l in la)
print("    levels 0 / 1 with the fit against without: bite %s N, max disp %s mm, energy %s mJ, vM max %s MPa; "
      "volume %+.2f %% -> %+.2f %%; energy change %+.2f %% against %+.2f %%; core %s" % (
          pair("bite_force_N", "%.2f"), pair("max_displacement_mm", "%.4f"), pair("strain_energy_mJ", "%.2f"),
          pair("von_mises_max_MPa", "%.2f"), 100 * a["mesh"]["fidelity"]["volume_difference"],
          100 * b["mesh"]["fidelity"]["volume_difference"], 100 * b["validation"]["relative_change"]["strain_energy"],
          100 * a["validation"]["relative_change"]["strain_energy"], b["mesh"].get("core")))

# 7. The sheet mesher against the shipped core.
for name in ("lateral_sheets", "lateral_bite_hard_nut"):
    r = load(name)
    la = r["validation"]["levels"]
    q, f = r["mesh"]["quality"], r["mesh"]["fidelity"]
    print("%s (%s%s): %s hexes, %s N (%+.2f %%), meshing %.2f s, run %.2f s; Hausdorff %.2f mm, volume %+.2f %%, "
          "SJ min %.3f / mean %.3f" % (
              name, r["mesh_method"], (" " + r["mesh"]["core"]) if "core" in r["mesh"] else "",
              " / ".join(str(l["hexes"]) for l in la), " / ".join("%.2f" % l["bite_force_N"] for l in la),
              100 * r["validation"]["relative_change"]["bite_force"], r["seconds"]["mesh_per_level"][0],
              r["seconds"]["total"], f["hausdorff_mm"], 100 * f["volume_difference"],
              q["scaled_jacobian"]["min"], q["scaled_jacobian"]["mean"]))
EOF
