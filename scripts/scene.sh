#!/usr/bin/env bash
# Builds and renders the scenes in assets/: voxelize, bake (lightsim) and render (viewer) headless.
#
#   bash scripts/scene.sh [NAME...|all] [--out DIR] [--scale F] [--res N] [--size WxH]
#                         [--backend auto|gl|cpu] [--no-render] [--build DIR] [--quiet] [--list]
#
# Each scene is a folder assets/NAME/ with SCENE.json (what the viewer renders) and build.sh (the
# voxelize and lightsim commands that make its volumes). A scene is built into DIR/NAME/ (default
# DIR: build/scenes): SCENE.json is copied there, the volumes are written beside it, so is the
# environment map it names (from assets/env/; a scene may name files in its own folder only, see
# docs/programs.md "Paths inside files"), and the render goes to DIR/NAME.png. Afterwards
#   build/viewer/viewer DIR/NAME/SCENE.json
# opens the scene in a window. DIR/NAME/times.json records the image size, the renderer and the
# voxelize, bake and render times.
#   --scale F     multiplies every resolution in the build.sh files (default 1)
#   --res N       uses N voxels along the longest axis for every volume instead (tests use 24)
#   --size WxH    image size (default: the scene's render.size)
#   --backend B   lightsim back end (default auto: the GPU path on a GPU, the CPU twin on llvmpipe)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
assets="$root/assets"
out="$root/build/scenes" scale=1 res_override="" size="" backend=auto render=1 bin="$root/build" quiet=""
names=()

all_scenes() { for d in "$assets"/*/; do [ -f "$d/SCENE.json" ] && basename "$d"; done; }

value() {  # value OPTION ARGS...: the option's argument, or a usage error
  [ $# -ge 2 ] && [ -n "$2" ] || { echo "scene.sh: $1 needs a value (see --help)" >&2; exit 2; }
  echo "$2"
}
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out=$(value "$@"); shift 2 ;;
    --scale) scale=$(value "$@"); shift 2 ;;
    --res) res_override=$(value "$@"); shift 2 ;;
    --size) size=$(value "$@"); shift 2 ;;
    --backend) backend=$(value "$@"); shift 2 ;;
    --no-render) render=0; shift ;;
    --build) bin=$(value "$@"); shift 2 ;;
    --quiet) quiet=--quiet; shift ;;
    --list) all_scenes; exit 0 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    -*) echo "scene.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
    all) mapfile -t -O "${#names[@]}" names < <(all_scenes); shift ;;
    *) names+=("$1"); shift ;;
  esac
done
[ ${#names[@]} -gt 0 ] || mapfile -t names < <(all_scenes)
for name in "${names[@]}"; do
  if [ ! -f "$assets/$name/SCENE.json" ] || [ ! -f "$assets/$name/build.sh" ]; then
    echo "scene.sh: no scene '$name' (assets/$name/SCENE.json and build.sh); scenes: $(all_scenes | tr '\n' ' ')" >&2
    exit 2
  fi
done
for program in voxelize/voxelize lightsim/lightsim viewer/viewer; do
  if [ ! -x "$bin/$program" ]; then
    echo "scene.sh: $bin/$program is missing; build first (bash scripts/build.sh)" >&2
    exit 2
  fi
done
if [ ! -s "$assets/env/studio.exr" ]; then
  echo "scene.sh: the environment maps in assets/env/ are missing; run bash scripts/fetch_assets.sh" >&2
  exit 2
fi
if [[ " ${names[*]} " == *" amber_bunny "* ]] && [ ! -s "$assets/meshes/bunny.obj" ]; then
  echo "scene.sh: assets/meshes/bunny.obj is missing; run bash scripts/fetch_assets.sh (it needs npm)" >&2
  exit 2
fi

mkdir -p "$out"
out=$(cd "$out" && pwd)

# What build.sh files call. They run inside DIR/NAME/, with ASSETS (assets/) and SCENE_DIR
# (assets/NAME/) set; lightsim bakes with the scene's first light.
res() {  # res N: N scaled by --scale, or --res
  if [ -n "$res_override" ]; then echo "$res_override"; else awk -v n="$1" -v s="$scale" 'BEGIN { printf "%d", n * s + 0.5 }'; fi
}
now() { date +%s.%N; }
timed() {  # timed KIND COMMAND...: runs it and adds its wall time to .times (KIND voxelize|bake)
  local kind=$1 t0; shift
  t0=$(now)
  "$@"
  awk -v k="$kind" -v a="$t0" -v b="$(now)" 'BEGIN { printf "%s %.3f\n", k, b - a }' >>.times
}
voxelize() { timed voxelize "$bin/voxelize/voxelize" "$@" $quiet; }
lightsim() { timed bake "$bin/lightsim/lightsim" "$@" --scene SCENE.json --backend "$backend" $quiet; }
total() { awk -v k="$1" '$1 == k { s += $2 } END { printf "%.1f", s }' "$2"; }
seconds() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.1f", b - a }'; }

i=0
for name in "${names[@]}"; do
  i=$((i + 1))
  dir="$out/$name"
  mkdir -p "$dir"
  cp "$assets/$name/SCENE.json" "$dir/SCENE.json"
  env_map=$(sed -n 's/.*"environment": *{"file": *"\([^"]*\)".*/\1/p' "$dir/SCENE.json")
  if [ -n "$env_map" ]; then
    cp -u "$assets/env/$env_map" "$dir/$env_map"
    cp -u "$assets/env/LICENSE.md" "$dir/LICENSE-environment.md"
  fi
  echo "scene.sh: [$i/${#names[@]}] $name: voxelize and bake into $dir"
  rm -f "$dir/.times"
  (cd "$dir" && ASSETS=$assets SCENE_DIR=$assets/$name && source "$assets/$name/build.sh")
  render_s=null image=null renderer=""
  if [ "$render" = 1 ]; then
    echo "scene.sh: [$i/${#names[@]}] $name: render"
    t3=$(now)
    viewer_says=$("$bin/viewer/viewer" "$dir/SCENE.json" --render "$out/$name.png" ${size:+--size "$size"} 2>&1) ||
      { echo "$viewer_says" >&2; exit 1; }
    render_s=$(seconds "$t3" "$(now)")
    renderer=$(echo "$viewer_says" | sed -n 's/.* with \(.*\)$/\1/p' | tail -1)
    image="\"$name.png\""
    echo "scene.sh: wrote $out/$name.png"
  fi
  printf '{"scene": "%s", "voxelize_s": %s, "bake_s": %s, "render_s": %s, "image": %s, "size": "%s", "renderer": "%s"}\n' \
    "$name" "$(total voxelize "$dir/.times")" "$(total bake "$dir/.times")" "$render_s" "$image" "${size:-scene}" "$renderer" \
    >"$dir/times.json"
  rm -f "$dir/.times"
done
