#!/usr/bin/env bash
# voxelize benchmark (issue "Foundation"): a procedural sphere and a 69,632-triangle torus (OBJ) at
# 64³, 128³ and 256³. Median of RUNS runs of the whole program (read, voxelise, smooth, ∇n, write
# raw NRRD), with the phases from --stats. Prints a Markdown table for BENCHMARKS.md.
# Usage: scripts/bench_voxelize.sh [RUNS=5] [BUILD_DIR=build]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
runs=${1:-5}
build=${2:-"$root/build"}
voxelize="$build/voxelize/voxelize"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Torus R = 1, r = 0.4, 256 x 136 quads -> 69,632 triangles.
/usr/bin/python3 - "$work/torus.obj" <<'PY'
import math, sys
U, V, R, r = 256, 136, 1.0, 0.4
with open(sys.argv[1], "w") as f:
    for i in range(U):
        a = 2 * math.pi * i / U
        for j in range(V):
            b = 2 * math.pi * j / V
            f.write("v %.9f %.9f %.9f\n" % ((R + r * math.cos(b)) * math.cos(a), r * math.sin(b), (R + r * math.cos(b)) * math.sin(a)))
    for i in range(U):
        for j in range(V):
            a, b = i * V + j + 1, ((i + 1) % U) * V + j + 1
            c, d = ((i + 1) % U) * V + (j + 1) % V + 1, i * V + (j + 1) % V + 1
            f.write("f %d %d %d\nf %d %d %d\n" % (a, d, c, a, c, b))
PY

median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
field() { /usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])" "$1" "$2"; }

echo "| input | grid | total s | occupancy s | smooth + ∇n s | write s | peak MiB |"
echo "| --- | --- | --- | --- | --- | --- | --- |"
for input in "procedural:sphere,r=0.5" "$work/torus.obj"; do
  label=$([ "$input" = "$work/torus.obj" ] && echo "torus, 69,632 triangles" || echo "sphere (procedural)")
  for res in 64 128 256; do
    : >"$work/t"; : >"$work/o"; : >"$work/f"; : >"$work/w"; : >"$work/m"
    for ((k = 0; k < runs; ++k)); do
      "$voxelize" "$input" -o "$work/out.vol.json" --res "$res" --raw --quiet --stats "$work/s.json"
      field "$work/s.json" time_total_s >>"$work/t"
      field "$work/s.json" time_occupancy_s >>"$work/o"
      field "$work/s.json" time_fields_s >>"$work/f"
      field "$work/s.json" time_write_s >>"$work/w"
      field "$work/s.json" peak_memory_mib >>"$work/m"
    done
    dims=$(/usr/bin/python3 -c "import json,sys; d=json.load(open(sys.argv[1]))['grid']['dims']; print('x'.join(map(str,d)))" "$work/s.json")
    printf "| %s | %s | %.3f | %.3f | %.3f | %.3f | %.0f |\n" "$label" "$dims" "$(median <"$work/t")" \
      "$(median <"$work/o")" "$(median <"$work/f")" "$(median <"$work/w")" "$(median <"$work/m")"
  done
done
