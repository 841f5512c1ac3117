#!/usr/bin/env bash
# An animated glTF scene on the wire: a volume baked at 2 s, served, and viewed remotely without
# --scene draws bit for bit what the in-process viewer draws at 2 s (the cube and the arm where
# they are then, not at 0 s); a live serve plays the animation and its viewers draw at the
# stream's clock. Bounded: the servers stop themselves; the script kills them when done.
set -euo pipefail
probecast=$1
work=$2
rm -rf "$work"
mkdir -p "$work"
scene=$(dirname "$0")/data/scenes/cornell-animated/cornell-animated.gltf
base=$((20000 + RANDOM % 20000))
pids=()
trap 'for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done' EXIT
"$probecast" bake --scene "$scene" --time 2 --grid 6,6,6 --spp 32 --updates 2 --out "$work/at2.pcpv" \
  | grep -q "at scene time 2"
"$probecast" serve --probes "$work/at2.pcpv" --scene "$scene" --listen "127.0.0.1:$base" --plaintext --token t0k \
  --seconds 30 >"$work/serve.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do grep -q "on port" "$work/serve.log" && break; sleep 0.1; done
export PROBECAST_SCENE_CACHE="$work/cache"
"$probecast" view --connect "127.0.0.1:$base" --token t0k --wait 1 --views mono --size 48x48 --exr \
  --out "$work/remote" | tee "$work/remote.log"
grep -q "drawn at scene time 2.0000" "$work/remote.log"
"$probecast" view --scene "$scene" --time 2 --probes "$work/at2.pcpv" --repr zh3 --views mono --size 48x48 --exr \
  --out "$work/local" >/dev/null
cmp "$work/remote/view_00.exr" "$work/local/view_00.exr"
# The same probes drawn with the geometry of 0 s are another picture.
"$probecast" view --scene "$scene" --time 0 --probes "$work/at2.pcpv" --repr zh3 --views mono --size 48x48 --exr \
  --out "$work/local0" >/dev/null
if cmp -s "$work/remote/view_00.exr" "$work/local0/view_00.exr"; then
  echo "the geometry did not move between 0 s and 2 s"; exit 1
fi
# Live: the updater traces the animation as it plays (1 scene second per second); a viewer
# follows the stream's clock.
live=$((base + 1))
"$probecast" serve --scene "$scene" --animate 1 --grid 4,4,4 --spp 32 --listen "127.0.0.1:$live" --plaintext \
  --token t0k --seconds 30 >"$work/live.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do grep -q "on port" "$work/live.log" && break; sleep 0.1; done
sleep 1
"$probecast" view --connect "127.0.0.1:$live" --token t0k --wait 1 --views mono --size 32x32 --exr \
  --out "$work/live-view" | tee "$work/live-view.log"
python3 - "$work/live-view.log" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
m = re.search(r"drawn at scene time ([0-9.]+) \(display clock\); probes traced at ([0-9.]+)", text)
assert m, text
shown, traced = float(m.group(1)), float(m.group(2))
assert shown > 0.5 and traced > 0.5, (shown, traced)
print("live animation: drawn at %.3f s, probes of %.3f s" % (shown, traced))
PY
# --time alone names a moment: the producer traces it and its clock stands still there.
still=$((base + 2))
"$probecast" serve --scene "$scene" --time 0.3 --grid 4,4,4 --spp 32 --listen "127.0.0.1:$still" --plaintext \
  --token t0k --seconds 30 >"$work/still.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do grep -q "on port" "$work/still.log" && break; sleep 0.1; done
sleep 2
"$probecast" view --connect "127.0.0.1:$still" --token t0k --wait 1 --views mono --size 32x32 \
  --out "$work/still-view" | tee "$work/still-view.log"
python3 - "$work/still-view.log" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
m = re.search(r"drawn at scene time ([0-9.]+) \(display clock\); probes traced at ([0-9.]+)", text)
assert m, text
shown, traced = float(m.group(1)), float(m.group(2))
assert abs(shown - 0.3) < 1e-3 and abs(traced - 0.3) < 1e-3, ("serve --time 0.3 did not stay at 0.3 s", shown, traced)
print("serve --time 0.3: drawn at %.3f s, probes of %.3f s" % (shown, traced))
PY
echo "animated scene round trip ok"
