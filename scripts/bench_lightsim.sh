#!/usr/bin/env bash
# lightsim benchmark (issue "lightsim"): bakes the glass sphere and the wine glass at the given
# resolutions with the GPU path (whatever OpenGL the machine has: llvmpipe here, EGL on a GPU
# machine) and the CPU twin, directional light straight down, default options. Each cell is the
# median of RUNS bakes (`lightsim --bench RUNS`; the volume is read and the GL context made once).
# Prints a Markdown table for BENCHMARKS.md.
#
# Usage: scripts/bench_lightsim.sh [RUNS=3] [RESOLUTIONS="64 128"] [BACKENDS="gl cpu"] [BUILD_DIR=build]
# Environment: LIGHTSIM_GL=auto|osmesa|egl (default auto; egl on a GPU machine without a display).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
runs=${1:-3}
resolutions=${2:-"64 128"}
backends=${3:-"gl cpu"}
build=${4:-"$root/build"}
voxelize="$build/voxelize/voxelize"
lightsim="$build/lightsim/lightsim"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

field() { /usr/bin/python3 -c "
import json, sys
v = json.load(open(sys.argv[1]))
for k in sys.argv[2].split('.'):
    v = v.get(k, {}) if isinstance(v, dict) else {}
print(v if v != {} else '')" "$1" "$2"; }

echo "| scene | grid | back end | median s | patch-steps | patch-steps/s | peak patches | texture MiB |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
for scene in sphere wine_glass; do
  for res in $resolutions; do
    "$voxelize" "procedural:$scene" -o "$work/$scene.vol.json" --res "$res" --raw --quiet
    for backend in $backends; do
      "$lightsim" "$work/$scene.vol.json" -o "$work/baked.vol.json" --light directional:0,-1,0 \
        --backend "$backend" --gl "${LIGHTSIM_GL:-auto}" --bench "$runs" --raw --quiet --stats "$work/s.json" >/dev/null
      grid=$(/usr/bin/python3 -c "import json,sys; print('x'.join(map(str, json.load(open(sys.argv[1]))['bench']['grid'])))" "$work/s.json")
      renderer=$(field "$work/s.json" renderer)
      tex=$(field "$work/s.json" texture_bytes.total_peak)
      tex_mib=$([ -n "$tex" ] && /usr/bin/python3 -c "print('%.0f' % ($tex / 1048576))" || echo "–")
      printf "| %s | %s | %s | %.2f | %s | %.2f M | %s | %s |\n" "$scene" "$grid" "${renderer%% (*}" \
        "$(field "$work/s.json" bench.median_s)" "$(field "$work/s.json" total_patches)" \
        "$(/usr/bin/python3 -c "print($(field "$work/s.json" bench.patch_steps_per_s) / 1e6)")" \
        "$(field "$work/s.json" peak_patches)" "$tex_mib"
    done
  done
done
