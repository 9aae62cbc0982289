#!/usr/bin/env bash
# The side-by-side benchmark of exact optics (BENCHMARKS.md): the glass sphere over a floor, rendered
# by the exact Monte Carlo tracer (tests/reference/exact_optics.h), by Eikonal (voxelize → lightsim
# → viewer) and by POV-Ray 3.7's photon map, all measured on this machine in one run and reduced to
# the same figures by tests/reference/ring_compare.cpp: the floor irradiance E in rings around the
# caustic's centre, the encircled flux Φ(r < 0.2) and Φ(r < 1), and the shadow radius.
#
# The scene: a sphere R = 1, n = 1.5, centre (0, 1.5, 0); the floor y = 0, albedo 0.8 (radiance
# 0.8/π · E); a sun straight down, irradiance 1 W/m²; no environment light.
#   exact    2·10⁷ rays, exact Fresnel, every bounce (ring_compare trace).
#   Eikonal  voxelize --res N --pad 2 (sharp interfaces; and --interfaces smooth at the largest N),
#            lightsim --scene (the ground is the receiver, half extent 4), then both
#            - "bake": the receiver map itself (ring_compare map), and
#            - "viewer": viewer --render floor.exr 256×256 from the camera below (ring_compare image).
#   POV-Ray  the same scene and camera, photons (ring_compare image --pov), at several photon counts.
# Each receiver map is also read against the exact tracer binned into that map's own texels
# (ring_compare trace --through-map): where E jumps at the shadow's edge, a ring measured by texel
# centres differs from the exact ring at any bake, and that row says by how much.
# The viewer and POV-Ray images are measured on the floor pixels whose straight ray from the eye
# misses the sphere grown to 1.05 (the camera sits low to the side, so it sees the floor under the
# sphere below it; ring_compare reports the fraction of each ring it sees).
#
# Usage: scripts/bench_exact_optics.sh [--out DIR] [--quick] [--build DIR] [--res "N..."]
#                                      [--backend auto|gl|cpu] [--no-pov] [--pov-counts "N..."]
#                                      [--exact FILE] [--bounces B] [--rounds R]
#   --out DIR      outputs (volumes, images, JSON, logs, table.md); default BUILD/bench-exact-optics
#   --quick        N = 32 and 64, 10⁶ tracer rays, one POV-Ray photon count, one run each (a test)
#   --build DIR    the build tree with voxelize, lightsim, viewer and tests/ring_compare (default build)
#   --res "N..."   Eikonal's grids (default "64 128"; the smoothed-interface row uses the last)
#   --backend B    lightsim's back end (default auto: the GPU path on a GPU, the CPU twin on llvmpipe);
#                  on a GPU server without a display, EIKONAL_GL=egl picks the OpenGL back end
#   --no-pov       leave POV-Ray out (a machine without it)
#   --pov-counts "N..."  POV-Ray's photon counts (default "100000 200000 400000 1600000"), e.g. to
#                  find the fewest photons at a given error
#   --exact FILE   the exact tracer's JSON of an earlier run instead of tracing again
#   --bounces B    lightsim's --bounces for every bake (default: lightsim's, one). On the sphere the
#                  light reflected three times inside it lands in the rings 0.4–0.9: with 3 the
#                  floor's error (0.4 %) falls below POV-Ray's at 1.6 M photons (BENCHMARKS.md,
#                  thirty-first and thirty-second parts)
#   --rounds R     then R rounds, alternated, of the whole pipeline (voxelize + bake + render at the
#                  first --res) and POV-Ray at the first photon count, one after the other in each
#                  round: both feel the machine's load alike. Prints their medians, the ratio of the
#                  medians and the spread of the per-round ratios (OUT/rounds.md)
# Needs the benchmark tool: cmake --build build --target ring_compare (EIKONAL_BUILD_BENCHMARKS and
# EIKONAL_BUILD_TESTS on). Installs the Debian package povray when `povray` is missing (as root).
# Prints the Markdown table on stdout (also OUT/table.md); progress goes to stderr.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build"
out=""
quick=0 res_option="" backend=auto pov=1 exact_file="" pov_option="" rounds=0 bounces=() bounce_label=""
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out=$2; shift 2 ;;
    --quick) quick=1; shift ;;
    --build) build=$2; shift 2 ;;
    --res) res_option=$2; shift 2 ;;
    --backend) backend=$2; shift 2 ;;
    --no-pov) pov=0; shift ;;
    --pov-counts) pov_option=$2; shift 2 ;;
    --exact) exact_file=$(cd "$(dirname "$2")" && pwd)/$(basename "$2"); shift 2 ;;
    --rounds) rounds=$2; shift 2 ;;
    --bounces) bounces=(--bounces "$2") bounce_label=" --bounces $2"; shift 2 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "bench_exact_optics.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
  esac
done
build=$(cd "$build" && pwd)
out=${out:-"$build/bench-exact-optics"}
mkdir -p "$out/logs"
out=$(cd "$out" && pwd)

if [ "$quick" = 1 ]; then
  resolutions="32 64"; rays=1e6; pov_counts="100000"; repeats=1
else
  resolutions="64 128"; rays=2e7; pov_counts="100000 200000 400000 1600000"; repeats=3
fi
resolutions=${res_option:-$resolutions}
pov_counts=${pov_option:-$pov_counts}
[ "$pov" = 1 ] || pov_counts=""
smooth_res=${resolutions##* }
# The camera of the viewer and of POV-Ray: low, to the side, looking at the caustic's centre.
eye="0,2.4,4.8"; target="0,0,0"; fov_y=36; width=256; height=256
camera="$eye:$target:$fov_y"

voxelize="$build/voxelize/voxelize"
lightsim="$build/lightsim/lightsim"
viewer="$build/viewer/viewer"
ring_compare="$build/tests/ring_compare"
for tool in "$voxelize" "$lightsim" "$viewer" "$ring_compare"; do
  [ -x "$tool" ] || { echo "bench_exact_optics.sh: $tool is missing (cmake --build $build --target ${tool##*/})" >&2; exit 2; }
done
# Run copies, so that a rebuild during the run cannot swap or remove a program half-way.
mkdir -p "$out/bin"
cp "$voxelize" "$lightsim" "$viewer" "$ring_compare" "$out/bin/"
voxelize="$out/bin/voxelize" lightsim="$out/bin/lightsim" viewer="$out/bin/viewer" ring_compare="$out/bin/ring_compare"
if [ "$pov" = 1 ] && ! command -v povray >/dev/null; then
  echo "bench_exact_optics.sh: installing povray (Debian package)" >&2
  DEBIAN_FRONTEND=noninteractive apt-get install -y povray >"$out/logs/apt-povray.log" 2>&1 ||
    { echo "bench_exact_optics.sh: apt-get install povray failed (see $out/logs/apt-povray.log)" >&2; exit 2; }
fi

log() { echo "[bench_exact_optics] $*" >&2; }
now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.2f", b - a }'; }
median() { printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { printf "%.2f", v[int((NR + 1) / 2)] }'; }
# Runs "$@" $repeats times, output to the log named by $run_log; echoes the median wall time.
timed() {
  local times=() t
  for _ in $(seq "$repeats"); do
    t=$(now)
    "$@" >>"$run_log" 2>&1
    times+=("$(since "$t")")
  done
  median "${times[@]}"
}

# --- the scenes --------------------------------------------------------------------------------
cat >"$out/bake_scene.json" <<EOF
{"comment": "bench_exact_optics.sh: the light and the ground (the receiver) for lightsim --scene",
 "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": [1, 1, 1]}],
 "ground": {"point": [0, 0, 0], "normal": [0, 1, 0], "albedo": [0.8, 0.8, 0.8], "half_extent": 4}}
EOF
view_scene() {  # $1 baked volume (relative to OUT) → the viewer's scene
  cat <<EOF
{"comment": "bench_exact_optics.sh: the floor seen from the side; camera = ring_compare image --camera $camera",
 "camera": {"eye": [${eye//,/, }], "target": [${target//,/, }], "up": [0, 1, 0], "fov_y_deg": $fov_y},
 "environment": {"uniform": [0, 0, 0]},
 "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": [1, 1, 1]}],
 "ground": {"point": [0, 0, 0], "normal": [0, 1, 0], "albedo": [0.8, 0.8, 0.8], "half_extent": 4},
 "objects": [{"volume": "$1"}],
 "render": {"size": [$width, $height], "tonemap": "linear"}}
EOF
}

# --- 1. exact ------------------------------------------------------------------------------------
log "exact tracer: $rays rays"
rays_text=$(awk -v r="$rays" 'BEGIN { e = int(log(r) / log(10) + 1e-9); m = r / 10 ^ e;
  if (m == 1) printf "10^%d", e; else printf "%g·10^%d", m, e }')
if [ -n "$exact_file" ]; then
  [ "$exact_file" = "$out/exact.json" ] || cp "$exact_file" "$out/exact.json"
else
  "$ring_compare" trace -o "$out/exact.json" --rays "$rays" --label "exact tracer ($rays_text rays)" \
    >"$out/logs/exact.log" 2>&1
fi
results=("$out/exact.json")

# --- 2. Eikonal --------------------------------------------------------------------------------
eikonal() {  # $1 resolution, $2 sharp|smooth
  local res=$1 mode=$2 name="sphere$1_$2" t vox bake render
  run_log="$out/logs/$name.log"
  : >"$run_log"
  log "Eikonal $res³ $mode: voxelize ($repeats×)"
  vox=$(timed "$voxelize" procedural:sphere,r=1,center=0:1.5:0,ior=1.5 -o "$out/$name.vol.json" --res "$res" \
    --pad 2 --interfaces "$mode")
  log "Eikonal $res³ $mode: bake ($repeats×)"
  bake=$(timed "$lightsim" "$out/$name.vol.json" -o "$out/$name.baked.vol.json" --scene "$out/bake_scene.json" \
    --backend "$backend" --stats "$out/$name.bake_stats.json" ${bounces[@]+"${bounces[@]}"})
  view_scene "$name.baked.vol.json" >"$out/$name.view.json"
  log "Eikonal $res³ $mode: render ($repeats×)"
  render=$(timed "$viewer" "$out/$name.view.json" --render "$out/$name.floor.exr" --size "${width}x$height")
  "$ring_compare" map "$out/$name.baked.vol.json" -o "$out/$name.map.json" \
    --label "Eikonal $res³ $mode$bounce_label: bake (receiver map)" --time "voxelize=$vox" --time "bake=$bake" >>"$run_log" 2>&1
  "$ring_compare" image "$out/$name.floor.exr" --camera "$camera" -o "$out/$name.image.json" \
    --label "Eikonal $res³ $mode$bounce_label: viewer image" --time "render=$render" >>"$run_log" 2>&1
  # The exact answer seen through this map's texels (binned by texel centre like the map): at the
  # shadow's edge a texel-centre ring mixes in its neighbour's light, bake or no bake.
  "$ring_compare" trace --through-map "$out/$name.baked.vol.json" --rays "$rays" -o "$out/$name.exact_map.json" \
    --label "exact through the $res³ $mode map's texels" >>"$run_log" 2>&1
  results+=("$out/$name.exact_map.json" "$out/$name.map.json" "$out/$name.image.json")
}
for res in $resolutions; do eikonal "$res" sharp; done
eikonal "$smooth_res" smooth

# --- 3. POV-Ray --------------------------------------------------------------------------------
# POV-Ray is left-handed (x right, y up, z into the screen): the world's z is mirrored (POV z = −z),
# which keeps the image the same (checked: a floor pigment encoding x and z decodes to the floor
# points ring_compare computes, to the EXR's half-float precision). `angle` is the horizontal field
# of view: 2·atan(aspect·tan(fov_y/2)). The parallel light casts no falloff; the floor's colour is
# pigment · diffuse · light · cos θ = 0.8·E (no 1/π): ring_compare image --pov divides by 0.8, and
# the far ring (direct light) checks that scale. The glass has Fresnel reflection with
# conserve_energy (without it POV-Ray transmits 100 %); photons carry the light refracted and
# reflected by the sphere, and a refractive photon target casts a full shadow for direct light.
IFS=, read -r ex ey ez <<<"$eye"
IFS=, read -r tx ty tz <<<"$target"
pov_angle=$(awk -v f="$fov_y" -v w="$width" -v h="$height" \
  'BEGIN { pi = atan2(0, -1); printf "%.10g", 2 * atan2(w / h * sin(f * pi / 360) / cos(f * pi / 360), 1) * 180 / pi }')
pov_scene() {  # $1 photon count
  cat <<EOF
// bench_exact_optics.sh: the glass sphere over a floor for POV-Ray 3.7 (z mirrored: POV z = -world z).
#version 3.7;
global_settings {
  assumed_gamma 1.0
  max_trace_level 10
  adc_bailout 0
  photons { count $1 autostop 0 jitter 0.4 max_trace_level 10 adc_bailout 0 }
}
background { rgb 0 }
camera { perspective location <$ex, $ey, $(awk -v z="$ez" 'BEGIN { print -z }')> look_at <$tx, $ty, $(awk -v z="$tz" 'BEGIN { print -z }')>
         right x * $width / $height up y angle $pov_angle }
light_source { <0, 100, 0> color rgb 1 parallel point_at <0, 0, 0> }
sphere { <0, 1.5, 0>, 1
  material {
    texture { pigment { rgbf <1, 1, 1, 1> } finish { ambient 0 diffuse 0 reflection { 0, 1 fresnel on } conserve_energy } }
    interior { ior 1.5 }
  }
  photons { target 1.0 reflection on refraction on }
}
plane { y, 0 pigment { rgb 0.8 } finish { ambient 0 diffuse 1 } }
EOF
}
[ "$pov" = 0 ] || pov_version=$(povray --version 2>&1 | grep -m1 -o 'POV-Ray [0-9.]*[a-z.]*' || echo POV-Ray)
for count in $pov_counts; do
  name="pov_$count"
  run_log="$out/logs/$name.log"
  : >"$run_log"
  pov_scene "$count" >"$out/$name.pov"
  log "POV-Ray photons count $count ($repeats×)"
  pov_s=$(cd "$out" && timed povray "+I$name.pov" "+O$name.exr" +FE "+W$width" "+H$height" -D +WT2 -P)
  shot=$(tr '\r' '\n' <"$run_log" | awk '/Number of photons shot/ { v = $NF } END { print v }')
  stored=$(tr '\r' '\n' <"$run_log" | awk '/Surface photons stored/ { v = $NF } END { print v }')
  photon_s=$(tr '\r' '\n' <"$run_log" | awk '/Photon Time:/ { gsub(/[()]/, "", $(NF-1)); v = $(NF-1) } END { print v }')
  "$ring_compare" image "$out/$name.exr" --pov --camera "$camera" -o "$out/$name.json" \
    --label "$pov_version photons: count $count ($shot shot, $stored stored)" --time "render=$pov_s" >>"$run_log" 2>&1
  log "  photons shot $shot, stored $stored, photon pass ${photon_s:-?} s of $pov_s s"
  results+=("$out/$name.json")
done

# --- 4. the table --------------------------------------------------------------------------------
cpu=$(awk -F': ' '/model name/ { print $2; exit }' /proc/cpuinfo)
{
  bake_renderer=$(/usr/bin/env python3 -c "import json, sys; print(json.load(open(sys.argv[1]))['renderer'])" \
    "$out/sphere${resolutions##* }_sharp.bake_stats.json" 2>/dev/null || echo "?")
  echo "Machine: $(uname -m), $(nproc) cores, ${cpu:-unknown CPU}; bake: $bake_renderer;" \
    "viewer: ${EIKONAL_GL:-auto} OpenGL (llvmpipe unless a GPU's EGL is picked)$([ "$pov" = 1 ] && echo "; POV-Ray +WT2")."
  echo "Camera (viewer and POV-Ray): eye ($eye), target ($target), fov_y $fov_y°, ${width}x$height, 1 ray/pixel."
  echo "Exact row: E in W/m², Φ in W. Other rows: ratio to exact per ring, deviation of Φ, shadow radius."
  echo "The row under it: the tracer's own noise per ring (1σ of its mean E, from the paths it counted); a"
  echo "deviation below it is not resolved ($rays rays: --quick's 10⁶ leave ±1.6 % in the ring 0.6-0.9)."
  echo "Times: median of $repeats runs of each command (wall seconds)."
  echo "Image rows (viewer, POV-Ray) point-sample the floor once per pixel (footprint about 0.011 x 0.025 near"
  echo "the caustic), which undersamples its core (a quarter of the flux of the ring 0-0.1 lies within r < 0.01):"
  echo "their ring 0-0.1 and Φ measure the camera's sampling as much as the renderer. The mean deviation"
  echo "leaves the ring 0-0.1 out (lightsim/exact_optics_test.cpp's measure)."
  echo
  "$ring_compare" compare "${results[@]}"
} | tee "$out/table.md"

# --- 5. rounds: the pipeline against POV-Ray, alternated --------------------------------------------
# Each round runs the three commands a user types (a fresh voxelization, bake and render of the
# first resolution) and POV-Ray at the first photon count, in turn first: the two share the round's
# load, so the per-round ratio is steadier than the ratio of two separate medians on a shared
# machine, and each follows the other equally often (on a virtual machine the first command after
# another that freed its memory can run 100–200 ms slower, its fresh pages faulted in by the host).
if [ "$rounds" -gt 0 ] && [ "$pov" = 1 ]; then
  res=${resolutions%% *} count=${pov_counts%% *} name="rounds"
  run_log="$out/logs/rounds.log"
  : >"$run_log"
  [ -f "$out/pov_$count.pov" ] || pov_scene "$count" >"$out/pov_$count.pov"
  view_scene "$name.baked.vol.json" >"$out/$name.view.json"
  ms() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.0f", (b - a) * 1000 }'; }
  {
    echo "Rounds: Eikonal ${res}³ (voxelize + bake + render ${width}x$height) and POV-Ray ($count photons), alternated"
    echo "(POV-Ray first in the even rounds); wall ms."
    echo
    echo "| round | voxelize | bake | render | Eikonal | POV-Ray | ratio |"
    echo "| ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
  } >"$out/rounds.md"
  eik_all=() pov_all=() ratios=()
  for r in $(seq "$rounds"); do
    log "round $r of $rounds"
    pov_first=$((r % 2 == 0))
    if [ "$pov_first" = 1 ]; then
      tp=$(now)
      (cd "$out" && povray "+Ipov_$count.pov" "+Orounds_pov.exr" +FE "+W$width" "+H$height" -D +WT2 -P >>"$run_log" 2>&1)
      p=$(ms "$tp" "$(now)")
    fi
    t0=$(now)
    "$voxelize" procedural:sphere,r=1,center=0:1.5:0,ior=1.5 -o "$out/$name.vol.json" --res "$res" --pad 2 \
      --interfaces sharp -q >>"$run_log" 2>&1
    t1=$(now)
    "$lightsim" "$out/$name.vol.json" -o "$out/$name.baked.vol.json" --scene "$out/bake_scene.json" \
      --backend "$backend" -q ${bounces[@]+"${bounces[@]}"} >>"$run_log" 2>&1
    t2=$(now)
    "$viewer" "$out/$name.view.json" --render "$out/$name.floor.exr" --size "${width}x$height" -q >>"$run_log" 2>&1
    t3=$(now)
    if [ "$pov_first" = 0 ]; then
      (cd "$out" && povray "+Ipov_$count.pov" "+Orounds_pov.exr" +FE "+W$width" "+H$height" -D +WT2 -P >>"$run_log" 2>&1)
      p=$(ms "$t3" "$(now)")
    fi
    e=$(ms "$t0" "$t3")
    eik_all+=("$e") pov_all+=("$p") ratios+=("$(awk -v p="$p" -v e="$e" 'BEGIN { printf "%.2f", p / e }')")
    echo "| $r | $(ms "$t0" "$t1") | $(ms "$t1" "$t2") | $(ms "$t2" "$t3") | $e | $p | ${ratios[-1]} |" >>"$out/rounds.md"
  done
  e_med=$(median "${eik_all[@]}") p_med=$(median "${pov_all[@]}")
  {
    echo
    echo "Medians: Eikonal $e_med ms, POV-Ray $p_med ms: POV-Ray takes $(awk -v p="$p_med" -v e="$e_med" 'BEGIN { printf "%.2f", p / e }')×" \
      "as long; per-round ratios: median $(median "${ratios[@]}"), lowest $(printf '%s\n' "${ratios[@]}" | sort -g | head -1)," \
      "highest $(printf '%s\n' "${ratios[@]}" | sort -g | tail -1)."
  } >>"$out/rounds.md"
  echo
  cat "$out/rounds.md"
fi
