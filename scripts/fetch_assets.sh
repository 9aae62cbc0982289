#!/usr/bin/env bash
# Prepares the third-party data the scenes in assets/ use; no third-party data is committed.
#   assets/env/*.exr       CC0 HDRIs (Greg Zaal, HDRI Haven) from Debian's blender-data package,
#                          converted to 512x256 half-float EXRs with oiiotool
#   assets/meshes/bunny.obj the Stanford bunny from the npm package "bunny" (public domain),
#                          centred and scaled to a height of 1 world unit
# Idempotent and quick when everything is there. Called by scripts/setup.sh.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
env_dir="$root/assets/env"
mesh_dir="$root/assets/meshes"
mkdir -p "$env_dir" "$mesh_dir"
world=/usr/share/blender/datafiles/studiolights/world

for name in courtyard studio sunset interior forest night city sunrise; do
  out="$env_dir/$name.exr"
  [ -s "$out" ] && continue
  if [ ! -f "$world/$name.exr" ]; then
    echo "fetch_assets: $world/$name.exr is missing (install the Debian package blender-data)" >&2
    exit 1
  fi
  oiiotool "$world/$name.exr" --resize 512x256 -d half -o "$out.tmp.exr"
  mv "$out.tmp.exr" "$out"
  echo "fetch_assets: wrote $out"
done

bunny="$mesh_dir/bunny.obj"
if [ ! -s "$bunny" ]; then
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
  echo "fetch_assets: fetching the Stanford bunny from npm (package bunny@1.0.1)"
  if npm install --no-save --no-audit --no-fund --loglevel=error --prefix "$tmp" bunny@1.0.1 >/dev/null &&
     node "$root/scripts/bunny_to_obj.js" "$tmp/node_modules/bunny" "$bunny.tmp"; then
    mv "$bunny.tmp" "$bunny"
    echo "fetch_assets: wrote $bunny"
  else
    rm -f "$bunny.tmp"
    echo "fetch_assets: warning: could not fetch the bunny from npm; the amber_bunny scene needs it" >&2
  fi
fi
