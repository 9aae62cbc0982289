#!/usr/bin/env bash
# Builds the libFuzzer harnesses (fuzz/, clang with ASan + UBSan) in build-fuzz/ and runs them on
# their seed corpus (fuzz/corpus/NAME/) with their dictionary (fuzz/NAME.dict where there is one).
#
#   bash scripts/fuzz.sh [--smoke | --seconds S] [--jobs J] [NAME...]
#
#   --smoke      the CI run: each harness for a fixed number of inputs (-runs=20000, -seed=1), so a
#                run is repeatable
#   --seconds S  a campaign: each harness for S seconds (default 60), J processes at once (default 1);
#                new inputs go to build-fuzz/corpus/NAME/ (the seeds stay as they are), crashes to
#                build-fuzz/crashes/NAME/
#   NAME         nrrd, manifest, volume, scene, obj, gltf, image (default: all)
# Prints each harness's executions and exits 1 at the first crash, leaving the reproducer named.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build-fuzz"
mode=seconds seconds=60 jobs=1 names=()
while [ $# -gt 0 ]; do
  case "$1" in
    --smoke) mode=smoke; shift ;;
    --seconds) seconds=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    -*) echo "fuzz.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
    *) names+=("$1"); shift ;;
  esac
done
[ ${#names[@]} -gt 0 ] || names=(nrrd manifest volume scene obj gltf image)
command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ is missing (bash scripts/setup.sh installs it)" >&2; exit 2; }
if [ ! -f "$build/CMakeCache.txt" ]; then
  CC=clang CXX=clang++ cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DEIKONAL_FUZZ=ON \
    -DEIKONAL_BUILD_TESTS=OFF -DEIKONAL_BUILD_BENCHMARKS=OFF >/dev/null
else
  cmake -S "$root" -B "$build" >/dev/null  # picks up harnesses added since the build folder was made
fi
targets=()
for name in "${names[@]}"; do targets+=("fuzz_$name"); done
cmake --build "$build" -j"$(nproc 2>/dev/null || echo 2)" --target "${targets[@]}"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=0:abort_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
for name in "${names[@]}"; do
  seeds="$root/fuzz/corpus/$name"
  dict=()
  [ -f "$root/fuzz/$name.dict" ] && dict=(-dict="$root/fuzz/$name.dict")
  crashes="$build/crashes/$name"
  mkdir -p "$crashes" "$build/corpus/$name"
  log="$build/$name.log"
  if [ "$mode" = smoke ]; then
    runs=20000
    # New inputs go to a scratch folder emptied first (the first corpus folder is where libFuzzer
    # writes): the seeds stay as committed, and the run starts from them alone.
    rm -rf "$build/smoke-corpus/$name" && mkdir -p "$build/smoke-corpus/$name"
    args=(-runs="$runs" -seed=1 "$build/smoke-corpus/$name" "$seeds")
  else
    args=(-max_total_time="$seconds" -jobs="$jobs" -workers="$jobs" "$build/corpus/$name" "$seeds")
  fi
  # -timeout: an input that runs 25 s (ASan included) is a hang, reported as a crash (libFuzzer's
  # default, 1200 s, let stb_image's endless loop on a cut .hdr scanline pass as a slow campaign).
  if ! (cd "$build" && "./fuzz/fuzz_$name" "${dict[@]}" -artifact_prefix="$crashes/" -rss_limit_mb=2048 -timeout=25 \
        -max_len=65536 -detect_leaks=0 -print_final_stats=1 "${args[@]}" >"$log" 2>&1); then
    echo "fuzz.sh: fuzz_$name found a crash; its log: $log" >&2
    grep -E "ERROR|SUMMARY|Test unit written" "$build"/fuzz-*.log "$log" 2>/dev/null | head -20 >&2 || true
    exit 1
  fi
  # Executions: each process's "stat::number_of_executed_units" (-print_final_stats). With -jobs
  # the workers log to fuzz-J.log in the working directory and libFuzzer copies each worker's log
  # into its own when the worker ends: the count is taken from that copy alone (counting fuzz-J.log
  # as well had counted every input twice, up to and including stop 19's campaigns).
  runs=$( (cat "$log" 2>/dev/null || true) |
          grep -oE "stat::number_of_executed_units: *[0-9]+" | grep -oE "[0-9]+" |
          awk '{ s += $1 } END { print s + 0 }')
  rm -f "$build"/fuzz-*.log
  echo "fuzz.sh: fuzz_$name: $runs inputs, no crash"
done
# The harnesses' input folders (eikonal-fuzz-PID) of processes that have ended; not those of a
# campaign still running beside this one.
for dir in /dev/shm/eikonal-fuzz-* /tmp/eikonal-fuzz-*; do
  [ -d "$dir" ] || continue
  kill -0 "${dir##*-}" 2>/dev/null || rm -rf "$dir"
done
