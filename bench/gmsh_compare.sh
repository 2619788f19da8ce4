#!/usr/bin/env bash
# bench/gmsh_compare.sh [BUILD_DIR]: the Gmsh peer benchmark of issue 3.
#
# For the real jaw (../shared/data/jaw/jaw_smooth.stl) and the built-in mandible, at about 2,500-4,000 and
# 20,000-30,000 hexes, meshes the solid with Gmsh 4.8.4 all-hex by tetrahedral subdivision (every tet split
# into four hexes) and with `hexbite mesh --method grid`, measures both with `hexbite quality --json` (the same
# metric code, DESIGN.md section 3) and prints a Markdown table: mesher, surface, hexes, inverted, scaled
# Jacobian min / mean, condition number max (cube = 3), volume difference against the surface's enclosed
# volume (`hexbite surface check`), wall seconds.
#
# Route chosen for Gmsh, and why: Gmsh meshes the tets, we do the 4-hex split ourselves (split_tets below).
# - A volume bounded directly by the STL keeps every STL triangle as a boundary face (41,760 on the jaw), so
#   its coarsest mesh has tens of thousands of hexes; comparable counts need the surface remeshed, i.e.
#   `ClassifySurfaces` (60 degrees, as DESIGN.md says works on the jaw) + `CreateGeometry`.
# - With that route, Gmsh 4.8.4's own `Mesh.SubdivisionAlgorithm = 2` writes some new boundary nodes at 1e21
#   (checked: 368 of 29,064 hexes inverted on the jaw at size 4.5), and in the direct-STL route face-centre
#   nodes at the origin and mirror-ordered hexes. Repairing those means guessing where a node should have been.
# - The split of the same tets is exactly what SubdivisionAlgorithm = 2 does (corner, three edge midpoints,
#   three face centroids, the tet centroid; checked: the same 4 x tets hexes, 29,064 on the jaw), with straight
#   edge midpoints (Gmsh may curve boundary midpoints onto the geometry), positively oriented by construction,
#   and needs no repair. The split's volume equals the tet mesh's volume exactly (its boundary quads are
#   planar). Its cost, a linear pass (Python here, well under a second), is not counted in Gmsh's seconds.
#
# Runs one process at a time (2 shared cores: parallel runs would distort the times), every command under a
# timeout so the script always stops, and writes only into a temp folder that is removed on exit.
set -euo pipefail

BUILD_DIR=${1:-build}
HEXBITE=$BUILD_DIR/app/hexbite
JAW=$(cd "$(dirname "$0")/../.." && pwd)/shared/data/jaw/jaw_smooth.stl
# Wall-clock limit per command (s): a hung mesher must not keep the benchmark (and the machine) busy forever.
LIMIT=900

[[ -x $HEXBITE ]] || { echo "gmsh_compare: $HEXBITE not found; build it first (ninja -C $BUILD_DIR hexbite)" >&2; exit 2; }
command -v gmsh >/dev/null || { echo "gmsh_compare: gmsh is not on the PATH (apt-get install gmsh)" >&2; exit 2; }
command -v python3 >/dev/null || { echo "gmsh_compare: python3 is needed for the tet split" >&2; exit 2; }
[[ -f $JAW ]] || { echo "gmsh_compare: the real jaw $JAW is missing" >&2; exit 2; }

TMP=$(mktemp -d "${TMPDIR:-/tmp}/gmsh_compare.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
# An interrupt or kill ends the script through `exit`, so the EXIT trap above still removes the folder.
trap 'exit 130' INT TERM

# The helper: `split IN.msh OUT.msh` (Gmsh 2.2 tets -> 2.2 hexes) and `row ...` (one table row from the
# quality JSON). Standard library only.
cat > "$TMP/helper.py" <<'PY'
import json, sys

def read_tets(path):
    """Nodes {tag: (x, y, z)} and the tets (type 4) of a Gmsh 2.2 ASCII file; other elements are skipped."""
    nodes, tets = {}, []
    with open(path) as f:
        lines = iter(f.read().split('\n'))
    for line in lines:
        if line.startswith('$MeshFormat') and not next(lines).startswith('2.2 0'):
            sys.exit('gmsh_compare: ' + path + ' is not Gmsh 2.2 ASCII')
        elif line.startswith('$Nodes'):
            for _ in range(int(next(lines))):
                t = next(lines).split()
                nodes[int(t[0])] = tuple(map(float, t[1:4]))
        elif line.startswith('$Elements'):
            for _ in range(int(next(lines))):
                t = list(map(int, next(lines).split()))
                if t[1] == 4:
                    tets.append(t[3 + t[2]:7 + t[2]])
    return nodes, tets

def det(p, q, r, s):
    u, v, w = ([b[i] - p[i] for i in range(3)] for b in (q, r, s))
    return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
            + u[2] * (v[0] * w[1] - v[1] * w[0]))

def split_tets(src, dst):
    """Every tet into four hexes, one per corner a (with the others b, c, e in positive order):
    a, mid(ab), centroid(abc), mid(ac) / mid(ae), centroid(abe), centroid(abce), centroid(ace) in VTK order.
    Shared edge midpoints and face centroids are created once (keyed by the sorted node ids)."""
    nodes, tets = read_tets(src)
    if not tets:
        sys.exit('gmsh_compare: no tetrahedra in ' + src)
    pts = list(nodes.values())
    index = {tag: i for i, tag in enumerate(nodes)}
    made = {}
    def mean_node(ids):
        key = tuple(sorted(ids))
        if key not in made:
            made[key] = len(pts)
            pts.append(tuple(sum(pts[i][c] for i in key) / len(key) for c in range(3)))
        return made[key]
    hexes = []
    for t in tets:
        v = [index[n] for n in t]
        if det(*(pts[i] for i in v)) < 0:  # Gmsh writes positive tets; make sure anyway
            v[2], v[3] = v[3], v[2]
        g = mean_node(v)
        # Even permutations of (v0, v1, v2, v3) keep the orientation, so each corner's hex is positive.
        for a, b, c, e in ((v[0], v[1], v[2], v[3]), (v[1], v[0], v[3], v[2]),
                           (v[2], v[3], v[0], v[1]), (v[3], v[2], v[1], v[0])):
            hexes.append((a, mean_node((a, b)), mean_node((a, b, c)), mean_node((a, c)),
                          mean_node((a, e)), mean_node((a, b, e)), g, mean_node((a, c, e))))
    with open(dst, 'w') as f:
        f.write('$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n%d\n' % len(pts))
        f.writelines('%d %.17g %.17g %.17g\n' % (i + 1, *p) for i, p in enumerate(pts))
        f.write('$EndNodes\n$Elements\n%d\n' % len(hexes))
        f.writelines('%d 5 2 1 1 %s\n' % (i + 1, ' '.join(str(n + 1) for n in h)) for i, h in enumerate(hexes))
        f.write('$EndElements\n')

def row(mesher, surface, quality_json, surface_json, seconds):
    q = json.load(open(quality_json))
    if 'volume_mm3' not in q:
        sys.exit('gmsh_compare: hexbite quality --json has no volume_mm3; rebuild hexbite')
    surface_volume = json.load(open(surface_json))['volume_mm3']
    diff = 100.0 * (q['volume_mm3'] - surface_volume) / surface_volume
    cond = q['condition']['max']
    print('| %s | %s | %d | %d | %.3f / %.3f | %s | %+.1f | %.1f |' % (
        mesher, surface, q['hexes'], q['inverted'], q['scaled_jacobian']['min'],
        q['scaled_jacobian']['mean'], 'n/a' if cond is None else '%.1f' % cond, diff, float(seconds)))

if __name__ == '__main__':
    {'split': split_tets, 'row': row}[sys.argv[1]](*sys.argv[2:])
PY

now() { date +%s.%N; }
elapsed() { python3 -c "import sys; print('%.2f' % (float(sys.argv[2]) - float(sys.argv[1])))" "$1" "$2"; }

# Gmsh's input: the STL as a discrete surface, classified into patches (60 degrees) and given a geometry so
# that it is remeshed at MeshSizeMax, then the volume inside it, meshed with tets (Delaunay, the default).
write_geo() {  # write_geo SURFACE SIZE OUT.geo
  cat > "$3" <<EOF
Merge "$1";
ClassifySurfaces{60 * Pi / 180, 1, 1, Pi};
CreateGeometry;
Surface Loop(1) = Surface{:};
Volume(1) = {1};
Mesh.MeshSizeMax = $2;
Mesh.MshFileVersion = 2.2;
EOF
}

"$HEXBITE" generate mandible -o "$TMP/mandible.stl" --landmarks "$TMP/mandible.yaml" > /dev/null

# surface label, path, then Gmsh MeshSizeMax (mm) and our --target-hexes for the coarse and the fine size.
# The Gmsh sizes were picked (2026-11-22) so the hex counts land in the wanted ranges: jaw 13 mm -> 2,968
# hexes, 4.5 mm -> 29,064. The built-in mandible has 35 patches after classification (teeth, sharp ridges)
# and Gmsh does not go below about 5,000-5,600 hexes on it at any size (18 mm and 22 mm give the same mesh),
# so its coarse row is Gmsh's coarsest; ours stays at about 3,000 there (a smaller count, as the issue allows).
CASES=(
  "real jaw|$JAW|13|3000|4.5|25000"
  "built-in mandible|$TMP/mandible.stl|18|3000|5|25000"
)

echo "gmsh_compare: $(gmsh --version 2>&1), $(uptime)" >&2
ROWS=()
for c in "${CASES[@]}"; do
  IFS='|' read -r label surface gsize1 target1 gsize2 target2 <<< "$c"
  timeout "$LIMIT" "$HEXBITE" surface check "$surface" --json > "$TMP/surface.json"
  for size in coarse fine; do
    if [[ $size == coarse ]]; then gsize=$gsize1; target=$target1; else gsize=$gsize2; target=$target2; fi

    write_geo "$surface" "$gsize" "$TMP/g.geo"
    t0=$(now)
    if ! timeout "$LIMIT" gmsh -3 "$TMP/g.geo" -o "$TMP/tets.msh" -v 2 > "$TMP/gmsh.log" 2>&1; then
      echo "gmsh_compare: gmsh failed on $label at size $gsize:" >&2; tail -20 "$TMP/gmsh.log" >&2; exit 1
    fi
    t1=$(now)
    gmsh_seconds=$(elapsed "$t0" "$t1")
    timeout "$LIMIT" python3 "$TMP/helper.py" split "$TMP/tets.msh" "$TMP/gmsh_hex.msh"
    echo "gmsh_compare: $label, Gmsh size $gsize mm: meshing $gmsh_seconds s, 4-hex split $(elapsed "$t1" "$(now)") s" >&2
    timeout "$LIMIT" "$HEXBITE" quality "$TMP/gmsh_hex.msh" --json > "$TMP/q_gmsh.json"
    ROWS+=("$(python3 "$TMP/helper.py" row "Gmsh 4.8.4 (tets, 4-hex split; size $gsize mm)" "$label" \
      "$TMP/q_gmsh.json" "$TMP/surface.json" "$gmsh_seconds")")

    t0=$(now)
    # --allow-invalid is not passed: a mesh that stays inverted is a failure of ours, recorded as such in the
    # table (the Gmsh rows are still worth printing), with hexbite's message on stderr.
    rc=0
    timeout "$LIMIT" "$HEXBITE" mesh "$surface" --method grid --target-hexes "$target" -o "$TMP/ours.vtu" \
      --json > "$TMP/mesh.json" || rc=$?
    ours_seconds=$(elapsed "$t0" "$(now)")
    if [[ $rc != 0 ]]; then
      ROWS+=("| hexbite grid (target $target) | $label | failed (exit $rc) | | | | | $ours_seconds |")
      continue
    fi
    timeout "$LIMIT" "$HEXBITE" quality "$TMP/ours.vtu" --json > "$TMP/q_ours.json"
    ROWS+=("$(python3 "$TMP/helper.py" row "hexbite grid (target $target)" "$label" \
      "$TMP/q_ours.json" "$TMP/surface.json" "$ours_seconds")")
  done
done

echo "| mesher | surface | hexes | inverted | scaled Jacobian min / mean | condition max (cube = 3) | volume difference % | seconds |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
printf '%s\n' "${ROWS[@]}"
