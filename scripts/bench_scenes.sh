#!/usr/bin/env bash
# The viewer on every scene in assets/ (issue "fast on two CPU cores", BENCHMARKS.md "The viewer in
# the scenes"): `viewer SCENE --bench FRAMES --size WxH` on each scene as scripts/scene.sh builds it,
# the full renderer against the bare march of the whole scene (every object's box and the ground;
# viewer/bench.h), medians of FRAMES frames. Prints a Markdown table. With --terms, a second table:
# what each term of the image formation model costs, the full frame's time less the time with that
# term switched off (--no-scattering, ...), in bare marches of the scene.
#
# Usage: scripts/bench_scenes.sh [--frames N] [--size WxH] [--scenes DIR] [--build DIR] [--terms] [NAME...]
#   --frames N    frames per renderer (default 3)
#   --terms       also time each term (six more runs a scene)
#   --size WxH    image size (default 800x600)
#   --scenes DIR  where scene.sh builds the scenes (default BUILD/scenes); scenes not built there
#                 yet are built first (minutes)
#   --build DIR   the build tree (default build)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
frames=3 size=800x600 build="$root/build" scenes="" names=() terms=0
while [ $# -gt 0 ]; do
  case "$1" in
    --frames) frames=$2; shift 2 ;;
    --size) size=$2; shift 2 ;;
    --scenes) scenes=$2; shift 2 ;;
    --build) build=$2; shift 2 ;;
    --terms) terms=1; shift ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
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
[ "$terms" = 1 ] || exit 0
# Each term's cost: the full frame less the frame without it, in bare marches (0: not in the scene).
term_flags=(--no-scattering --no-fresnel --no-attenuation --no-emission --no-dispersion --no-ground)
echo
echo "| scene | bare ms | full ms | scattering | Fresnel | attenuation | emission | dispersion | ground |"
echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
for name in "${names[@]}"; do
  for flag in "${term_flags[@]}"; do
    "$viewer" "$scenes/$name/SCENE.json" --bench "$frames" --size "$size" --stats "$work/$name$flag.json" --quiet "$flag"
  done
  /usr/bin/python3 - "$work" "$name" "${term_flags[@]}" <<'PY'
import json, sys
work, name, flags = sys.argv[1], sys.argv[2], sys.argv[3:]
full = json.load(open("%s/%s.json" % (work, name)))
bare, total = full["bare"]["median_ms"], full["full"]["median_ms"]
cells = []
for flag in flags:
    without = json.load(open("%s/%s%s.json" % (work, name, flag)))["full"]["median_ms"]
    cells.append("%.2f" % max(0.0, (total - without) / bare))
print("| %s | %.1f | %.1f | %s |" % (name, bare, total, " | ".join(cells)))
PY
done
