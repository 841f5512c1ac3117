#!/usr/bin/env bash
# `view --looking-glass`: a display's calibration picks the view set (8x6 on a portrait panel) and
# the views are interleaved into one panel-sized image; a broken calibration is refused by name,
# with nothing written.
set -euo pipefail
probecast=$1
work=$2
cal=$3
spatial=$4
rm -rf "$work"
mkdir -p "$work"
"$probecast" bake --scene builtin:cornell --grid 4,4,4 --spp 16 --updates 1 --out "$work/p.pcpv" >/dev/null
"$probecast" view --scene builtin:cornell --probes "$work/p.pcpv" --looking-glass "$cal" --size 24x32 --supersample 1 \
  --out "$work/lg" | tee "$work/lg.log"
grep -q "Looking Glass Portrait LKG-P-example (1536x2048): 48 views (8x6 quilt) of 24x32 across 40 degrees" "$work/lg.log"
/usr/bin/python3 - "$work/lg/looking_glass.png" "$work/lg/quilt.png" <<'PY'
import sys
import matplotlib.image as mpimg
panel, quilt = mpimg.imread(sys.argv[1]), mpimg.imread(sys.argv[2])
assert panel.shape[:2] == (2048, 1536), panel.shape
assert quilt.shape[:2] == (6 * 32, 8 * 24), quilt.shape
# Interleaved: neighbouring subpixels come from different views, so the panel is far from a
# smooth picture; but every value comes from the quilt.
assert panel[..., :3].std() > 0.01
print("looking glass panel %dx%d from a %dx%d quilt" % (panel.shape[1], panel.shape[0], quilt.shape[1], quilt.shape[0]))
PY
# A 16" Spatial landscape panel (a 2024 model, subpixel cells): its 7x7 view set at its aspect.
"$probecast" view --scene builtin:cornell --probes "$work/p.pcpv" --looking-glass "$spatial" --size 32x18 --supersample 1 \
  --out "$work/spatial" | tee "$work/spatial.log"
grep -q 'Looking Glass 16" Spatial (landscape) LKG-J-example (3840x2160, subpixel cells): 49 views (7x7 quilt) of 32x18 across 50 degrees' \
  "$work/spatial.log"
/usr/bin/python3 - "$work/spatial/looking_glass.png" <<'PY'
import sys
import matplotlib.image as mpimg
panel = mpimg.imread(sys.argv[1])
assert panel.shape[:2] == (2160, 3840), panel.shape
assert panel[..., :3].std() > 0.01
PY
# A calibration without its pitch.
grep -v '"pitch"' "$cal" >"$work/broken.json"
set +e
"$probecast" view --scene builtin:cornell --probes "$work/p.pcpv" --looking-glass "$work/broken.json" --out "$work/broken" \
  >"$work/broken.log" 2>&1
rc=$?
set -e
[ "$rc" -ne 0 ] || { echo "a calibration without pitch was taken"; exit 1; }
grep -q "pitch" "$work/broken.log" || { cat "$work/broken.log"; exit 1; }
[ ! -e "$work/broken/looking_glass.png" ]
echo "looking glass ok"
