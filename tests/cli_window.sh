#!/usr/bin/env bash
# The live window, for real: an X server (Xvfb), a GLFW window with a Vulkan swapchain on lavapipe.
# 0. Without a display the viewer says so and exits 1.
# 1. Local probes: a screenshot of the window is the offscreen render of the same camera, bit for
#    bit (EXR), and what was presented (read back from the swapchain) is its tone-mapped PNG below
#    the status line.
# 2. A server's stream (its token from a file): a key press (xdotool) writes a screenshot equal to the remote offscreen
#    render; the server is killed and the window keeps presenting frames and says it is
#    reconnecting; the server returns and the window is connected again.
set -euo pipefail
probecast=$1
work=$2
calibration=$3
rm -rf "$work"
mkdir -p "$work"
pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done; }
trap cleanup EXIT
Xvfb -displayfd 3 -screen 0 1024x768x24 -nolisten tcp 3>"$work/display" 2>"$work/xvfb.log" &
pids+=($!)
for _ in $(seq 100); do [ -s "$work/display" ] && break; sleep 0.1; done
export DISPLAY=":$(cat "$work/display")"
export PROBECAST_SCENE_CACHE="$work/cache"

"$probecast" bake --scene builtin:cornell --grid 4,4,4 --spp 16 --updates 1 --out "$work/p.pcpv" >/dev/null
view=(--views mono --size 160x96 --supersample 1)

# 0. No display: a clear error, nothing else.
set +e
env -u DISPLAY "$probecast" view --scene builtin:cornell --probes "$work/p.pcpv" "${view[@]}" --window \
  --out "$work/no-display" >"$work/no-display.log" 2>&1
rc=$?
set -e
[ "$rc" -eq 1 ] || { echo "no display: exit $rc"; exit 1; }
grep -q "cannot open a window: .*DISPLAY" "$work/no-display.log" || { cat "$work/no-display.log"; exit 1; }

# 1. Local probes (at full size throughout: --window-fps 0, so the screenshot is the render's).
"$probecast" view --scene builtin:cornell --probes "$work/p.pcpv" "${view[@]}" --window --window-seconds 5 \
  --window-fps 0 --screenshot-after 0.5 --out "$work/local-window" | tee "$work/local-window.log"
grep -q "window: 160x96 on" "$work/local-window.log"
"$probecast" view --scene builtin:cornell --probes "$work/p.pcpv" "${view[@]}" --exr --out "$work/local-off" >/dev/null
cmp "$work/local-window/screenshot_000.exr" "$work/local-off/view_00.exr"
/usr/bin/python3 - "$work/local-window/screenshot_000.png" "$work/local-off/quilt.png" "$work/local-window.log" <<'PY'
import re, sys
import matplotlib.image as mpimg
shot, off = mpimg.imread(sys.argv[1]), mpimg.imread(sys.argv[2])
assert shot.shape[:2] == off.shape[:2] == (96, 160), (shot.shape, off.shape)
band = 20  # the status line's band at scale 1 is about 16 rows
assert (abs(shot[band:, :, :3] - off[band:, :, :3]) < 1e-6).all(), "presented pixels differ from the render"
assert (abs(shot[:band, :, :3] - off[:band, :, :3]) > 1e-3).any(), "no status line"
frames = int(re.search(r"closed after [0-9.]+ s, (\d+) frames presented", open(sys.argv[3]).read()).group(1))
assert frames >= 2, frames
print("local window: %d frames, screenshot equals the offscreen render" % frames)
PY

# Dynamic resolution: a rate no device holds at full size (1000 frames a second) draws the views at
# the smallest scale, a quarter a side, and the window still shows them at its own size.
"$probecast" view --scene builtin:cornell --probes "$work/p.pcpv" "${view[@]}" --window --window-seconds 3 \
  --window-fps 1000 --screenshot-after 2.5 --out "$work/fast-window" >"$work/fast-window.log"
grep -q "frames presented.*| drawn at 25 %" "$work/fast-window.log" || { cat "$work/fast-window.log"; exit 1; }
/usr/bin/python3 - "$work/fast-window/screenshot_000.png" <<'PY'
import sys
import matplotlib.image as mpimg
shot = mpimg.imread(sys.argv[1])
assert shot.shape[:2] == (96, 160), shot.shape
print("dynamic resolution: drawn at 25 %, shown at the window's 160x96")
PY

# A recorded head turns the camera: a second in, the head has turned 7-9 degrees, so the window's
# picture is not the still camera's; a trace that cannot be read is refused before any window.
"$probecast" view --scene builtin:cornell --probes "$work/p.pcpv" "${view[@]}" --window --window-seconds 3 \
  --screenshot-after 1 --head-trace builtin:mmsys18-user1 --out "$work/head-window" >"$work/head-window.log"
grep -q "window: the camera turns as builtin:mmsys18-user1 turned (10.0 s, looping)" "$work/head-window.log" ||
  { cat "$work/head-window.log"; exit 1; }
/usr/bin/python3 - "$work/head-window/screenshot_000.png" "$work/local-window/screenshot_000.png" <<'PY'
import sys
import matplotlib.image as mpimg
head, still = mpimg.imread(sys.argv[1]), mpimg.imread(sys.argv[2])
assert head.shape == still.shape, (head.shape, still.shape)
band = 20  # below the status line
differ = (abs(head[band:, :, :3] - still[band:, :, :3]).max(axis=2) > 0.02).mean()
assert differ > 0.2, "the head turned, the picture did not (%.3f of pixels differ)" % differ
print("head-tracked window: %.0f%% of pixels differ from the still camera's" % (100 * differ))
PY
set +e
"$probecast" view --scene builtin:cornell --probes "$work/p.pcpv" "${view[@]}" --window --head-trace builtin:nobody \
  --out "$work/bad-trace" >"$work/bad-trace.log" 2>&1
rc=$?
set -e
[ "$rc" -ne 0 ] && grep -q "builtin:nobody: no such trace" "$work/bad-trace.log" || { cat "$work/bad-trace.log"; exit 1; }
[ ! -e "$work/bad-trace" ]

# A Looking Glass panel's window on a smaller screen (1024x768 here) is shown at 1/3, not larger
# than the screen; --fullscreen would show it whole on the panel.
"$probecast" view --scene builtin:cornell --probes "$work/p.pcpv" --looking-glass "$calibration" --size 24x32 \
  --supersample 1 --window --window-seconds 2 --out "$work/lg-window" >"$work/lg-window.log"
grep -q "window: 1536x2048 is larger than the screen (1024x768): shown at 1/3" "$work/lg-window.log" &&
  grep -q "window: 512x682 on" "$work/lg-window.log" || { cat "$work/lg-window.log"; exit 1; }

# A window without --views opens one view of --size (not view's default set of 25).
"$probecast" view --scene builtin:cornell --probes "$work/p.pcpv" --size 160x96 --supersample 1 --window \
  --window-seconds 1 --out "$work/one-view" >"$work/one-view.log"
grep -q "window: 160x96 on" "$work/one-view.log" || { cat "$work/one-view.log"; exit 1; }

# 2. A server's stream, stopped and started again.
port=$((20000 + RANDOM % 20000))
serve() {
  "$probecast" serve --probes "$work/p.pcpv" --listen "127.0.0.1:$port" --plaintext --token t0k --seconds 60 \
    >>"$work/serve.log" 2>&1 &
  server=$!
  pids+=($server)
  for _ in $(seq 100); do [ "$(grep -c "on port" "$work/serve.log")" -ge "$1" ] && break; sleep 0.1; done
}
serve 1
"$probecast" view --connect "127.0.0.1:$port" --token t0k "${view[@]}" --exr --wait 1 --out "$work/remote-off" >/dev/null
printf 't0k\n' >"$work/token"
"$probecast" view --connect "127.0.0.1:$port" --token-file "$work/token" "${view[@]}" --window --window-seconds 90 \
  --out "$work/remote-window" >"$work/remote-window.log" 2>&1 &
viewer=$!
pids+=($viewer)
for _ in $(seq 150); do grep -q "connected to" "$work/remote-window.log" && break; sleep 0.1; done
id=$(xdotool search --sync --name probecast | head -1)
xdotool getwindowgeometry "$id" | grep -q "Geometry: 160x96"
xdotool windowfocus --sync "$id" 2>/dev/null || true
xdotool key --window "$id" p
for _ in $(seq 50); do [ -f "$work/remote-window/screenshot_000.exr" ] && break; sleep 0.1; done
sleep 0.5
cmp "$work/remote-window/screenshot_000.exr" "$work/remote-off/view_00.exr"
kill "$server"
wait "$server" 2>/dev/null || true
sleep 4
before=$(grep -c "frames presented" "$work/remote-window.log")
grep -q "reconnecting" "$work/remote-window.log"
serve 2
# Connected again after the reconnecting lines; then Escape closes the window.
for _ in $(seq 300); do
  sed -n '/reconnecting/,$p' "$work/remote-window.log" | grep -q "frames presented.*connected to" && break
  sleep 0.1
done
xdotool key --window "$id" Escape
wait "$viewer"
grep -q "window: closed after" "$work/remote-window.log"
python3 - "$work/remote-window.log" <<'PY'
import re, sys
lines = [l for l in open(sys.argv[1]) if l.startswith("window: ") and "frames presented," in l]
states = [("reconnecting" in l, "connected to" in l, int(re.search(r"(\d+) frames presented", l).group(1))) for l in lines]
first_down = next(i for i, s in enumerate(states) if s[0])
back = next(i for i, s in enumerate(states) if i > first_down and s[1])
down = [s[2] for s in states if s[0]]
assert down[-1] > down[0], "no frames while the server was away: %s" % down
print("remote window: frames %d..%d while the server was away, connected again after %d s"
      % (down[0], down[-1], back - first_down))
PY
echo "live window ok"
