#!/usr/bin/env bash
# Installs what Eikonal needs from Debian 12's packages, then prepares the scenes' third-party data
# (scripts/fetch_assets.sh: HDRIs from blender-data, the bunny from npm). Idempotent: does nothing
# (quickly) when everything is already there.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  libosmesa6-dev libegl-dev libegl-mesa0 libgl1-mesa-dri
  libglfw3-dev libglm-dev libopenexr-dev libpng-dev libstb-dev libtinygltf-dev python3-glad
  libhwy-dev  # Google Highway: SIMD in the CPU twin, dispatched at run time to the CPU's vectors
  libjemalloc-dev  # the programs' allocator (core/allocator.cpp): huge pages, fewer page faults
  openimageio-tools  # scripts: oiiotool converts the HDRIs (fetch_assets.sh) and the gallery's PNGs
  nlohmann-json3-dev libcli11-dev zlib1g-dev
  libdeflate-dev  # NRRD gzip data read many times faster than zlib's inflate (core/gzip_stream.cpp)
  libgtest-dev libgmock-dev libbenchmark-dev
  libimgui-dev
  xvfb xauth
  clang libclang-rt-14-dev  # scripts/fuzz.sh: libFuzzer harnesses (fuzz/)
  blender-data
)
# npm fetches the Stanford bunny (npm package "bunny"); Debian's npm brings Node.js with it.
command -v npm >/dev/null 2>&1 || packages+=(npm)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then
    SUDO="sudo"
  fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

"$(dirname "$0")/fetch_assets.sh"
