#!/usr/bin/env bash
# The viewer window's re-bake (viewer/background_bake.h) timed as it runs there: the CPU twin,
# `lightsim --bench RUNS` (the simulator made once, the median of RUNS bakes), full and coarse
# (--patch 2 --split 2 --receiver-pitch 0.5: the coarse bake's options), on scenes a user drags the
# sun in:
#   sphere  the exact-optics sphere over its floor (bench_exact_optics.sh), sun at 60° elevation
#   glass   assets/glass_sphere's volumes at N³ (the glass ball with its glowing core), its SCENE.json
# Prints a Markdown table (bakes per second = 1 / median).
# Usage: scripts/bench_rebake.sh [RUNS=3] [RESOLUTIONS="32 64"] [BUILD_DIR=build]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
runs=${1:-3}
resolutions=${2:-"32 64"}
build=${3:-$root/build}
voxelize="$build/voxelize/voxelize" lightsim="$build/lightsim/lightsim"
for tool in "$voxelize" "$lightsim"; do
  [ -x "$tool" ] || { echo "bench_rebake: $tool is missing; build first (bash scripts/build.sh)" >&2; exit 2; }
done
work=$(mktemp -d /tmp/eikonal-bench-rebake.XXXXXX)
trap 'rm -rf "$work"' EXIT
cat >"$work/sphere_scene.json" <<JSON
{"lights": [{"type": "directional", "direction": [0.5, -0.866, 0], "irradiance": [1, 1, 1]}],
 "ground": {"point": [0, 0, 0], "normal": [0, 1, 0], "albedo": [0.8, 0.8, 0.8], "half_extent": 4}}
JSON
cpu=$(grep -m1 "model name" /proc/cpuinfo | sed 's/.*: //')
echo "Re-bake in the viewer window: CPU twin, $(nproc) threads, $cpu; median of $runs bakes"
echo
echo "| scene | grid | quality | median bake | bakes/s | patch-steps |"
echo "| --- | --- | --- | ---: | ---: | ---: |"
for res in $resolutions; do
  "$voxelize" procedural:sphere,r=1,center=0:1.5:0,ior=1.5 -o "$work/sphere.vol.json" --res "$res" --pad 2 --quiet
  "$voxelize" procedural:sphere,r=0.45,center=0:-0.05:0 \
              procedural:sphere,r=0.12,center=0:-0.05:0,emission=6:2.6:0.7,name=core \
              -o "$work/glass.vol.json" --res "$res" --bounds -0.55,-0.53,-0.55,0.8,0.45,0.75 --quiet
  for scene in sphere glass; do
    if [ "$scene" = sphere ]; then bake_scene="$work/sphere_scene.json"; else bake_scene="$root/assets/glass_sphere/SCENE.json"; fi
    for quality in full coarse; do
      extra=()
      [ "$quality" = coarse ] && extra=(--patch 2 --split 2 --receiver-pitch 0.5)
      "$lightsim" "$work/$scene.vol.json" -o "$work/baked.vol.json" --scene "$bake_scene" --backend cpu \
                  --bench "$runs" --stats "$work/stats.json" --quiet "${extra[@]}" >/dev/null
      python3 - "$work/stats.json" "$scene" "$res" "$quality" <<'PY'
import json, sys
s = json.load(open(sys.argv[1])); b = s["bench"]
print("| %s | %s³ | %s | %.3f s | %.1f | %.3g M |" % (sys.argv[2], sys.argv[3], sys.argv[4], b["median_s"],
      1.0 / b["median_s"], s["total_patches"] / 1e6))
PY
    done
  done
done
