#!/usr/bin/env bash
# viewer benchmark (issue "viewer"): `viewer --bench` on the baked 128³ sphere and wine glass at
# 256², 512² and 800×600 — the full renderer (default settings: every term on; and again with
# --no-skip, without empty-space skipping) against the bare
# one-fetch refractive march of the same volume (viewer/bench.h), medians of FRAMES frames each.
# Samples = ray steps: counted exactly by the bare march; the full renderer's figure is that count
# over its own time (step-equivalent). Prints a Markdown table for BENCHMARKS.md.
#
# The baked volumes are cached under BUILD_DIR/bench-viewer/ (a 128³ bake takes minutes): delete
# that folder to rebake. RES=64 for a quicker run.
# Usage: scripts/bench_viewer.sh [FRAMES=10] [BUILD_DIR=build] [RES=128]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
frames=${1:-10}
build=${2:-"$root/build"}
res=${3:-128}
voxelize="$build/voxelize/voxelize"
lightsim="$build/lightsim/lightsim"
viewer="$build/viewer/viewer"
cache="$build/bench-viewer"
mkdir -p "$cache"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# name|voxelize input
scenes=(
  "sphere|procedural:sphere"
  "wine glass|procedural:wine_glass"
)

for entry in "${scenes[@]}"; do
  name=${entry%%|*}
  input=${entry#*|}
  stem=$(echo "$name" | tr ' ' '_')-$res
  if [ ! -f "$cache/$stem.vol.json" ]; then
    echo "bench_viewer: voxelizing $name at $res³" >&2
    "$voxelize" "$input" -o "$cache/$stem.vol.json" --res "$res" --quiet
  fi
  if [ ! -f "$cache/$stem.baked.vol.json" ]; then
    echo "bench_viewer: baking $name (lightsim --backend cpu; minutes)" >&2
    "$lightsim" "$cache/$stem.vol.json" -o "$cache/$stem.baked.vol.json" --light directional:0.3,-1,-0.2 \
      --backend cpu --quiet
  fi
done

field() { /usr/bin/python3 -c "
import json, sys
j = json.load(open(sys.argv[1]))
for k in sys.argv[2].split('.'):
    j = j[k]
print(j)" "$1" "$2"; }

renderer=""
echo "| scene | grid | image | full renderer | ray steps/frame | full ms/frame | full Msamples/s | bare ms/frame | bare Msamples/s | full/bare |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
for entry in "${scenes[@]}"; do
  name=${entry%%|*}
  stem=$(echo "$name" | tr ' ' '_')-$res
  for size in 256x256 512x512 800x600; do
   for variant in default --no-skip; do
    flags=()
    [ "$variant" = default ] || flags=("$variant")
    "$viewer" "$cache/$stem.baked.vol.json" --bench "$frames" --size "$size" --stats "$work/s.json" --quiet "${flags[@]}"
    renderer=$(field "$work/s.json" gl_renderer)
    printf "| %s | %s³ | %s | %s | %.2fM | %.1f | %.1f | %.1f | %.1f | %.2f |\n" "$name" "$res" "$size" "$variant" \
      "$(/usr/bin/python3 -c "print($(field "$work/s.json" bare.steps_per_frame) / 1e6)")" \
      "$(field "$work/s.json" full.median_ms)" \
      "$(/usr/bin/python3 -c "print($(field "$work/s.json" full.samples_per_s) / 1e6)")" \
      "$(field "$work/s.json" bare.median_ms)" \
      "$(/usr/bin/python3 -c "print($(field "$work/s.json" bare.samples_per_s) / 1e6)")" \
      "$(field "$work/s.json" ratio_full_over_bare)"
   done
  done
done
echo
echo "Medians of $frames frames (glFinish each; full and bare interleaved), $renderer, $(nproc) CPU cores."
echo "Ray steps counted by the bare march; the full renderer's samples/s is that count over its time"
echo "(step-equivalent: with empty-space skipping, the default, it takes fewer real steps)."
