#!/usr/bin/env bash
# The GPU measurements in one run (BENCHMARKS.md "On a real GPU"), for a machine with a GPU and no
# display: every program through EGL (EIKONAL_GL=egl), each part under a time limit so that a short
# lease still brings back what finished. Writes OUT/log.txt and one Markdown table per part:
#   lightsim.md   the GL bake against the CPU twin, sphere and wine glass (scripts/bench_lightsim.sh)
#   exact.md      the sphere over its floor, GL bake, against exact optics (bench_exact_optics.sh
#                 --backend gl --no-pov; --exact FILE reuses an exact tracer's JSON)
#   scenes.md     the viewer on every scene of assets/, full against bare march, each term's cost
#                 (scripts/bench_scenes.sh --terms; the scenes baked on the GPU path first)
#   viewer.md     the viewer on the lone 128³ volumes (scripts/bench_viewer.sh)
#   ctest.log     the test suite under EGL (no Xvfb there: the window tests are left out)
#
# Usage: scripts/bench_gpu.sh [--out DIR] [--build DIR] [--exact FILE] [--res "N..."] [--quick]
#   --out DIR     where the tables go (default BUILD/bench-gpu)
#   --build DIR   the build tree (default build)
#   --exact FILE  the exact tracer's JSON of an earlier bench_exact_optics.sh run (else traced here)
#   --res "N..."  the bake grids (default "64 128 256")
#   --quick       64³ only, 3 runs, no scenes or tests (a check that EGL works)
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build" out="" exact="" res="64 128 256" quick=0
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out=$2; shift 2 ;;
    --build) build=$2; shift 2 ;;
    --exact) exact=$2; shift 2 ;;
    --res) res=$2; shift 2 ;;
    --quick) quick=1; res=64; shift ;;
    -h|--help) sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "bench_gpu.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
  esac
done
build=$(cd "$build" && pwd) || exit 2
out=${out:-"$build/bench-gpu"}
mkdir -p "$out" && out=$(cd "$out" && pwd)
export EIKONAL_GL=${EIKONAL_GL:-egl} LIGHTSIM_GL=${LIGHTSIM_GL:-egl}
start=$(date +%s)
part() { echo; echo "=== [$(($(date +%s) - start)) s] $*"; }
{
  part "the OpenGL context"
  "$build/voxelize/voxelize" procedural:sphere -o "$out/probe.vol.json" --res 32 --quiet &&
    "$build/lightsim/lightsim" "$out/probe.vol.json" -o "$out/probe.baked.vol.json" --light directional:0,-1,0 \
      --backend gl --stats "$out/probe.json" --quiet || { echo "bench_gpu.sh: no GL bake with EIKONAL_GL=$EIKONAL_GL"; exit 2; }
  grep -m1 '"renderer"' "$out/probe.json"
  part "lightsim: GL against the CPU twin"
  timeout 300 bash "$root/scripts/bench_lightsim.sh" "$([ "$quick" = 1 ] && echo 3 || echo 5)" "$res" "gl cpu" "$build" |
    tee "$out/lightsim.md"
  part "the sphere over its floor against exact optics, GL bake"
  timeout 300 bash "$root/scripts/bench_exact_optics.sh" --out "$out/exact" --build "$build" --res "$res" --backend gl \
    --no-pov ${exact:+--exact "$exact"} $([ "$quick" = 1 ] && echo --quick) | tee "$out/exact.md"
  if [ "$quick" = 0 ]; then
    part "the scenes of assets/: GL bakes, then the viewer at 800x600"
    timeout 300 bash "$root/scripts/scene.sh" all --backend gl --out "$out/scenes" --build "$build" --quiet
    timeout 300 bash "$root/scripts/bench_scenes.sh" --frames 10 --terms --scenes "$out/scenes" --build "$build" |
      tee "$out/scenes.md"
    part "the viewer on lone volumes"
    timeout 300 bash "$root/scripts/bench_viewer.sh" 10 "$build" | tee "$out/viewer.md"
    part "the test suite under EGL"
    timeout 600 ctest --test-dir "$build" -j"$(nproc)" --timeout 120 -E "Xvfb|Window" --output-on-failure \
      >"$out/ctest.log" 2>&1
    grep -E "tests passed|^\s+[0-9]+ - " "$out/ctest.log"
  fi
  part done
} 2>&1 | tee "$out/log.txt"
