#!/usr/bin/env bash
# The viewer on every scene in assets/ (issue "fast on two CPU cores", BENCHMARKS.md "The viewer in
# the scenes"): `viewer SCENE --bench FRAMES --size WxH` on each scene as scripts/scene.sh builds it,
# the full renderer against the bare march of the whole scene (every object's box and the ground;
# viewer/bench.h), medians of FRAMES frames. Prints a Markdown table.
#
# Usage: scripts/bench_scenes.sh [--frames N] [--size WxH] [--scenes DIR] [--build DIR] [NAME...]
#   --frames N    frames per renderer (default 3)
#   --size WxH    image size (default 800x600)
#   --scenes DIR  where scene.sh builds the scenes (default BUILD/scenes); scenes not built there
#                 yet are built first (minutes)
#   --build DIR   the build tree (default build)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
frames=3 size=800x600 build="$root/build" scenes="" names=()
while [ $# -gt 0 ]; do
  case "$1" in
    --frames) frames=$2; shift 2 ;;
    --size) size=$2; shift 2 ;;
    --scenes) scenes=$2; shift 2 ;;
    --build) build=$2; shift 2 ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    -*) echo "bench_scenes.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
    *) names+=("$1"); shift ;;
  esac
done
scenes=${scenes:-"$build/scenes"}
if [ ${#names[@]} -eq 0 ]; then
  for d in "$root"/assets/*/; do [ -f "$d/SCENE.json" ] && names+=("$(basename "$d")"); done
fi
viewer="$build/viewer/viewer"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "| scene | objects | image | full ms/frame | bare ms/frame | full/bare |"
echo "| --- | ---: | --- | ---: | ---: | ---: |"
for name in "${names[@]}"; do
  if [ ! -f "$scenes/$name/SCENE.json" ] || ! ls "$scenes/$name"/*.vol.json >/dev/null 2>&1; then
    echo "bench_scenes: building $name (scripts/scene.sh)" >&2
    bash "$root/scripts/scene.sh" "$name" --out "$scenes" --build "$build" --no-render --quiet >&2
  fi
  "$viewer" "$scenes/$name/SCENE.json" --bench "$frames" --size "$size" --stats "$work/$name.json" --quiet
  /usr/bin/python3 - "$work/$name.json" "$name" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
print("| %s | %d | %dx%d | %.1f | %.1f | %.2f |" % (sys.argv[2], j["bare_objects"], j["size"][0], j["size"][1],
      j["full"]["median_ms"], j["bare"]["median_ms"], j["ratio_full_over_bare"]))
PY
done
