#!/usr/bin/env bash
# serve a baked volume over loopback, subscribe, and compare what arrived with what was served.
# Bounded: the server stops itself after 20 s; the script kills it when done.
set -euo pipefail
probecast=$1
work=$2
mkdir -p "$work"
port=$((20000 + RANDOM % 20000))
"$probecast" bake --scene builtin:cornell --grid 6,6,6 --spp 32 --updates 1 --out "$work/served.pcpv" >/dev/null
printf '  s3cret \n\n' >"$work/token"  # whitespace around the token is not part of it
"$probecast" serve --probes "$work/served.pcpv" --repr l2 --deadzone 0 --listen "127.0.0.1:$port" --plaintext \
  --token-file "$work/token" --seconds 20 >"$work/serve.log" 2>&1 &
server=$!
trap 'kill $server 2>/dev/null || true' EXIT
for _ in $(seq 50); do grep -q "on port" "$work/serve.log" && break; sleep 0.1; done
"$probecast" subscribe --connect "127.0.0.1:$port" --token s3cret --seconds 1 --out "$work/received.pcpv"
if "$probecast" subscribe --connect "127.0.0.1:$port" --token wrong --seconds 1 2>"$work/refused.log"; then
  echo "a wrong token was accepted"; exit 1
fi
grep -q "wrong bearer token" "$work/refused.log"
# The received volume is the l2 decoding of the served one: same size, within quantisation error.
python3 - "$work/served.pcpv" "$work/received.pcpv" <<'PY'
import struct, sys
def load(p):
    b = open(p, 'rb').read()
    n = struct.unpack_from('<3I', b, 8)
    count = n[0] * n[1] * n[2]
    f = struct.unpack_from('<%df' % (count * 27), b, 52)
    return count, f, b[52 + count * 108: 52 + count * 109]
ca, fa, ma = load(sys.argv[1]); cb, fb, mb = load(sys.argv[2])
assert ca == cb and ma == mb, "grid or active mask differ"
num = sum((x - y) ** 2 for x, y in zip(fa, fb)); den = sum(x * x for x in fa)
rel = (num / den) ** 0.5
print("relative coefficient error %.4f" % rel)
assert rel < 0.02, rel
PY
# Snapshots at multiples of 0.25 s on the system clock: consecutive ticks, each the volume held
# (a file served as is: every snapshot equals the final volume, byte for byte).
rm -rf "$work/snaps"
"$probecast" subscribe --connect "127.0.0.1:$port" --token s3cret --seconds 1.2 --snapshot-every 0.25 \
  --snapshot-dir "$work/snaps" --out "$work/received-snap.pcpv" | tee "$work/snap.log"
python3 - "$work/snaps" "$work/received-snap.pcpv" <<'PY'
import os, sys
names = sorted(os.listdir(sys.argv[1]))
ticks = [int(n[:-5]) for n in names if n.endswith(".pcpv")]
assert len(ticks) == len(names) and 2 <= len(ticks) <= 5, names
assert ticks == list(range(ticks[0], ticks[0] + len(ticks))), ticks
final = open(sys.argv[2], "rb").read()
assert all(open(os.path.join(sys.argv[1], n), "rb").read() == final for n in names), "a snapshot differs"
print("%d snapshots, consecutive ticks, each the served volume" % len(ticks))
PY
grep -q "snapshots in $work/snaps" "$work/snap.log"
# A coarser representation is transcoded by the server; a finer one is refused.
"$probecast" subscribe --connect "127.0.0.1:$port" --token s3cret --seconds 1 --repr l1 --out "$work/received-l1.pcpv"
if "$probecast" subscribe --connect "127.0.0.1:$port" --token s3cret --seconds 1 --repr fp16 2>"$work/finer.log"; then
  echo "a finer representation than the stream's was served"; exit 1
fi
grep -q "transcodes it only to coarser ones" "$work/finer.log"
python3 - "$work/served.pcpv" "$work/received.pcpv" "$work/received-l1.pcpv" <<'PY'
import struct, sys
def load(p):
    b = open(p, 'rb').read()
    n = struct.unpack_from('<3I', b, 8)
    count = n[0] * n[1] * n[2]
    return struct.unpack_from('<%df' % (count * 27), b, 52)
served, l2, l1 = (load(p) for p in sys.argv[1:])
# l1 holds no L2 band (coefficients 4..8 of every probe are 0) and keeps the DC as l2 does.
band = max(abs(v) for p in range(len(l1) // 27) for v in l1[p * 27 + 12: p * 27 + 27])
assert band == 0.0, band
dc = max(abs(a - b) for p in range(len(l1) // 27) for a, b in zip(l1[p * 27: p * 27 + 3], l2[p * 27: p * 27 + 3]))
assert dc < 1e-3 * max(served), dc
print("transcoded l1: no L2 band, DC as the l2 stream's")
PY
# A per-brick representation: the same file served with an error bound; what the subscriber holds
# is within the bound of what was served (relative irradiance error, exact over the sphere: every
# brick is, so the whole volume is).
port2=$((port + 1))
"$probecast" serve --probes "$work/served.pcpv" --repr l2 --deadzone 0 --error-bound 0.1 --listen "127.0.0.1:$port2" \
  --plaintext --no-auth --seconds 20 >"$work/serve2.log" 2>&1 &
server2=$!
trap 'kill $server $server2 2>/dev/null || true' EXIT
for _ in $(seq 50); do grep -q "on port" "$work/serve2.log" && break; sleep 0.1; done
"$probecast" subscribe --connect "127.0.0.1:$port2" --seconds 1 --out "$work/received-bound.pcpv"
python3 - "$work/served.pcpv" "$work/received-bound.pcpv" <<'PY'
import struct, sys, math
def load(p):
    b = open(p, 'rb').read()
    n = struct.unpack_from('<3I', b, 8)
    count = n[0] * n[1] * n[2]
    return count, struct.unpack_from('<%df' % (count * 27), b, 52), b[52 + count * 108: 52 + count * 109]
count, served, active = load(sys.argv[1])
_, got, _ = load(sys.argv[2])
band = [math.pi] + [2 * math.pi / 3] * 3 + [math.pi / 4] * 5
err = energy = 0.0
for p in range(count):
    if not active[p]:
        continue
    err += sum(band[i] ** 2 * (got[p * 27 + i * 3 + c] - served[p * 27 + i * 3 + c]) ** 2 for i in range(9) for c in range(3))
    energy += sum(band[i] ** 2 * served[p * 27 + i * 3 + c] ** 2 for i in range(9) for c in range(3))
rel = (err / energy) ** 0.5
print("error bound 0.1: volume error %.4f" % rel)
assert rel <= 0.1 + 1e-4, rel
PY
# The raster client fed by the stream.
"$probecast" view --connect "127.0.0.1:$port" --token s3cret --wait 1 --views stereo --size 24x16 --out "$work/view" \
  | grep -q "2 views"
# A 9x9 light field (81 views) subscribes over gRPC as well.
"$probecast" view --connect "127.0.0.1:$port" --token s3cret --wait 1 --views lf:9x9 --size 8x8 --out "$work/view-lf" \
  | grep -q "81 views"
# The stream names its scene: a viewer without --scene draws the same image as one given the
# scene and the probe file in-process (same camera, same representation), bit for bit.
export PROBECAST_SCENE_CACHE="$work/scene-cache"
"$probecast" view --connect "127.0.0.1:$port" --token s3cret --wait 1 --views mono --size 24x16 --exr \
  --out "$work/remote" | tee "$work/remote.log" | grep -q "named by the stream"
"$probecast" view --scene builtin:cornell --probes "$work/served.pcpv" --repr l2 --views mono --size 24x16 --exr \
  --out "$work/local" >/dev/null
cmp "$work/remote/view_00.exr" "$work/local/view_00.exr"
# Another scene than the stream's is refused, naming both; so is a time of the viewer's own.
if "$probecast" view --connect "127.0.0.1:$port" --token s3cret --scene builtin:hall --wait 1 --views mono \
  --size 8x8 --out "$work/wrong" 2>"$work/wrong.log"; then
  echo "a viewer drew another scene than the stream's"; exit 1
fi
grep -q "not the scene the server traces: yours is builtin:hall (scene [0-9a-f]*), the stream's builtin:cornell" \
  "$work/wrong.log"
if "$probecast" view --connect "127.0.0.1:$port" --token s3cret --t 0.5 --views mono --size 8x8 \
  --out "$work/t" 2>"$work/t.log"; then
  echo "a viewer of a stream drew at a time of its own"; exit 1
fi
grep -q "draws at the stream's scene clock" "$work/t.log"
echo "serve/subscribe round trip ok"
