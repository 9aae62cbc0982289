#!/usr/bin/env bash
# Regenerates the gallery: builds, bakes and renders every scene in assets/ at --scale (default
# 1.5, finer than the demo), copies the pictures to docs/gallery/ (PNG, at most 300 KB each) and
# writes docs/gallery.md with each scene's file, grids, bake and render times and thesis figure.
#   bash scripts/gallery.sh [--scale F] [--reuse] [SCENE...]
# --reuse skips the builds and renders and remakes the page from build/gallery/.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
scale=1.5 reuse=0
names=()
while [ $# -gt 0 ]; do
  case "$1" in
    --scale) scale=$2; shift 2 ;;
    --reuse) reuse=1; shift ;;
    -h|--help) sed -n '2,6p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) names+=("$1"); shift ;;
  esac
done
work="$root/build/gallery"
if [ "$reuse" = 0 ]; then
  "$root/scripts/setup.sh"
  "$root/scripts/build.sh" "$root/build"
  bash "$root/scripts/scene.sh" --out "$work" --scale "$scale" "${names[@]}"
fi

mkdir -p "$root/docs/gallery"
for png in "$work"/*.png; do
  target="$root/docs/gallery/$(basename "$png")"
  cp "$png" "$target"
  # Keep each picture under 300 KB: shrink by 10 % steps if needed.
  width=$(oiiotool --info -v "$png" | sed -n 's/.*: *\([0-9]*\) x *\([0-9]*\),.*/\1/p' | head -1)
  while [ "$(stat -c %s "$target")" -gt 300000 ]; do
    width=$((width * 9 / 10))
    oiiotool "$png" --resize "${width}x0" -o "$target"
  done
done

python3 - "$root" "$work" "$scale" <<'PY'
import datetime, json, os, platform, re, sys
root, work, scale = sys.argv[1], sys.argv[2], sys.argv[3]
cpu = next((l.split(':', 1)[1].strip() for l in open('/proc/cpuinfo') if l.startswith('model name')), platform.machine())
cores = os.cpu_count()
scenes = sorted(d for d in os.listdir(work) if os.path.isfile(os.path.join(work, d, 'times.json')))
out = ['# Gallery', '',
       'Every picture here is rendered by `bash scripts/gallery.sh` (it regenerates this page): each scene in',
       '[`assets/`](../assets) is voxelized, baked with `lightsim` and rendered headless by `viewer`, with the',
       'commands of its `build.sh` at `--scale %s` (the demo uses 1). Times are wall-clock seconds on %s,' % (scale, cpu),
       '%d cores, no GPU: `lightsim --backend auto` bakes with the CPU twin there, and the viewer renders on Mesa\'s' % cores,
       'llvmpipe. Generated %s.' % datetime.date.today().isoformat(), '']
for name in scenes:
    t = json.load(open(os.path.join(work, name, 'times.json')))
    build = open(os.path.join(root, 'assets', name, 'build.sh')).read().splitlines()
    caption = []
    for line in build:
        if not line.startswith('#'): break
        caption.append(line.lstrip('# ').rstrip())
    scene = json.load(open(os.path.join(work, name, 'SCENE.json')))
    grids, backends = [], set()
    for obj in scene['objects']:
        m = json.load(open(os.path.join(work, name, obj['volume'])))
        grids.append('×'.join(str(d) for d in m['dims']))
        if 'bake_stats' in m: backends.add(m['bake_stats'].get('renderer', m['bake_stats'].get('backend', '?')))
    img = 'gallery/%s.png' % name
    w, h = scene['render']['size']
    out += ['## %s' % name.replace('_', ' ').capitalize(), '',
            '![%s](%s)' % (name, img), '', ' '.join(caption), '',
            '| | |', '| --- | --- |',
            '| thesis | %s |' % (re.search(r'\(thesis (Fig[^)]*)\)', ' '.join(caption)) or [None, '–'])[1],
            '| scene | [`assets/%s/SCENE.json`](../assets/%s/SCENE.json), built by [`build.sh`](../assets/%s/build.sh) |' % (name, name, name),
            '| volumes | %s voxels |' % ', '.join(grids),
            '| voxelize | %.1f s |' % t['voxelize_s'],
            '| bake | %s |' % ('%.1f s (%s)' % (t['bake_s'], ', '.join(sorted(backends))) if backends else 'none (nothing in it needs light)'),
            '| render | %dx%d in %.1f s (%s; the first frame, shader compilation included) |' % (w, h, t['render_s'], t['renderer'] or '?'),
            '']
open(os.path.join(root, 'docs', 'gallery.md'), 'w').write('\n'.join(out))
print('gallery: wrote', os.path.join(root, 'docs', 'gallery.md'))
PY
ls -la "$root"/docs/gallery/
