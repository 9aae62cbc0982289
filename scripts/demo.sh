#!/usr/bin/env bash
# The demo: sets up a fresh Debian 12 machine (if needed), builds Release (if needed), then
# voxelizes, bakes and renders the thesis' scenes in assets/ headless (scripts/scene.sh) and writes
# the pictures into demo-output/. About a minute on two CPU cores once built (scripts/build.sh takes 3-4 more the first time).
#   bash scripts/demo.sh [SCENE...] [--scale F]     (default: every scene, --scale 1)
# --scale multiplies the scenes' resolutions; scripts/gallery.sh renders them at full size.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out="$root/demo-output"
"$root/scripts/setup.sh"
"$root/scripts/build.sh" "$root/build"

args=("$@")
case " ${args[*]-} " in *" --scale "*) ;; *) args+=(--scale 1) ;; esac
start=$(date +%s)
bash "$root/scripts/scene.sh" --out "$out" "${args[@]}"
echo
echo "demo: done in $(( $(date +%s) - start )) s. Pictures:"
ls -1 "$out"/*.png
echo "demo: open a scene in the window (needs a display):  $root/build/viewer/viewer $out/wine_glass/SCENE.json"
