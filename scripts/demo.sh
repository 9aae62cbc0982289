#!/usr/bin/env bash
# The demo: sets up a fresh Debian 12 machine (if needed), builds Release, voxelizes the thesis'
# procedural objects and renders a headless preview of each. Images land in demo-output/.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out="$root/demo-output"
"$root/scripts/setup.sh"
"$root/scripts/build.sh" "$root/build"
bin="$root/build"
mkdir -p "$out"

# name | voxelize input | resolution | viewer camera | environment
scenes=(
  "wine_glass|procedural:wine_glass|128|0,0.55,2.1:0,0.45,0:35|checker:1,1,1"
  "logo_block|procedural:logo_block|128|1.2,0.8,1.9:0,0,0:35|checker:1,1,1"
  "layered_cube|procedural:layered_cube|96|1.6,1.2,1.6:0,0,0:35|checker:1,1,1"
  "luneburg|procedural:luneburg|96|0,0,2.6:0,0,0:30|checker:1,1,1"
)
for entry in "${scenes[@]}"; do
  IFS='|' read -r name input res camera env <<<"$entry"
  echo "demo: $name"
  "$bin/voxelize/voxelize" "$input" -o "$out/$name.vol.json" --res "$res" --stats "$out/$name.voxelize.json"
  "$bin/viewer/viewer" "$out/$name.vol.json" --render "$out/$name.png" --size 512x512 --camera "$camera" --env "$env"
done
echo
echo "demo: images and volumes are in $out"
ls -1 "$out"/*.png
