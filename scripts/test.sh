#!/usr/bin/env bash
# Sets up a fresh Debian 12 machine (if needed), builds Release and runs the whole test suite.
# Usage: scripts/test.sh            Release build in build/
#        scripts/test.sh --sanitize ASan + UBSan build in build-sanitize/
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh"
if [ "${1:-}" = "--sanitize" ]; then
  build="$root/build-sanitize"
  "$root/scripts/build.sh" "$build" -DEIKONAL_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo
  export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=0:abort_on_error=1}
  export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
else
  build="$root/build"
  "$root/scripts/build.sh" "$build"
fi
cd "$build"
ctest --output-on-failure -j"$(nproc 2>/dev/null || echo 2)" --timeout 300
