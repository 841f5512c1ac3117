#!/usr/bin/env bash
# serve a baked volume and publish it to a nats-server started here; two edges serve it; a
# subscriber given a dead address first and then the edges ends with the same volume as one
# subscribed to the producer directly. Bounded: everything stops itself after 30 s; the script
# kills what it started when done.
set -euo pipefail
probecast=$1
work=$2
rm -rf "$work"
mkdir -p "$work"
nats=$(command -v nats-server || true)
for d in /usr/sbin /usr/bin; do [ -n "$nats" ] || { [ -x "$d/nats-server" ] && nats=$d/nats-server; }; done
if [ -z "$nats" ]; then echo "nats-server not found (a dependency: scripts/setup.sh installs it)"; exit 1; fi
base=$((20000 + RANDOM % 20000))
np=$base sp=$((base + 1)) ea=$((base + 2)) eb=$((base + 3)) dead=$((base + 4))
pids=()
trap 'for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done' EXIT
# The bus requires a token, as a deployment's should; it is in files, not on command lines.
printf 'bus-%s\n' "$RANDOM$RANDOM" >"$work/bus-token"
printf 'authorization { token: "%s" }\n' "$(cat "$work/bus-token")" >"$work/nats.conf"
"$nats" -c "$work/nats.conf" -a 127.0.0.1 -p "$np" -js -sd "$work/nats" >"$work/nats.log" 2>&1 &
pids+=($!)
bus=(--nats-token-file "$work/bus-token" --nats-plaintext)
# A glTF scene: its files go to the viewers with the stream (through the edges too).
scene=$(dirname "$0")/data/scenes/cornell-box/CornellBox-Original.gltf
"$probecast" bake --scene "$scene" --area-lights off --grid 6,6,6 --spp 32 --updates 1 --out "$work/served.pcpv" >/dev/null
"$probecast" serve --probes "$work/served.pcpv" --scene "$scene" --listen "127.0.0.1:$sp" --plaintext --token t0k --seconds 30 \
  --publish "nats://127.0.0.1:$np" --stream cli "${bus[@]}" >"$work/serve.log" 2>&1 &
pids+=($!)
printf 't0k\n' >"$work/scene-token"
for port in $ea $eb; do
  "$probecast" edge --nats "nats://127.0.0.1:$np" --stream cli "${bus[@]}" --listen "127.0.0.1:$port" --plaintext \
    --token t0k --seconds 30 --scene-from "127.0.0.1:$sp" --scene-from-token-file "$work/scene-token" \
    --scene-cache "$work/edge-cache-$port" >"$work/edge-$port.log" 2>&1 &
  pids+=($!)
done
for log in serve "edge-$ea" "edge-$eb"; do
  for _ in $(seq 100); do grep -q "on port" "$work/$log.log" && break; sleep 0.1; done
done
"$probecast" subscribe --connect "127.0.0.1:$sp" --token t0k --seconds 2 --out "$work/direct.pcpv" >/dev/null
"$probecast" subscribe --connect "127.0.0.1:$dead,127.0.0.1:$ea,127.0.0.1:$eb" --token t0k --seconds 2 \
  --out "$work/edge.pcpv" | tee "$work/subscribe.log"
cmp "$work/direct.pcpv" "$work/edge.pcpv"
# The wrong token is refused by an edge as by the producer.
if "$probecast" subscribe --connect "127.0.0.1:$eb" --token wrong --seconds 1 2>"$work/refused.log"; then
  echo "an edge accepted a wrong token"; exit 1
fi
grep -q "wrong bearer token" "$work/refused.log"
# A viewer of an edge without --scene: the scene arrives once (the edge fetched it from the
# producer), then comes from the viewer's cache; the image is the in-process one of the same file.
export PROBECAST_SCENE_CACHE="$work/viewer-cache"
for _ in $(seq 50); do grep -q "scene CornellBox" "$work/edge-$ea.log" 2>/dev/null && break; sleep 0.2; done
"$probecast" view --connect "127.0.0.1:$ea" --token t0k --wait 1 --views mono --size 24x16 --exr --out "$work/v1" \
  | tee "$work/v1.log" | grep -q "fetched from the server: [0-9]* bytes"
"$probecast" view --connect "127.0.0.1:$ea" --token t0k --wait 1 --views mono --size 24x16 --exr --out "$work/v2" \
  | grep -q "from the cache"
"$probecast" view --scene "$scene" --probes "$work/served.pcpv" --repr zh3 --views mono --size 24x16 --exr \
  --out "$work/local" >/dev/null
cmp "$work/v1/view_00.exr" "$work/local/view_00.exr"
cmp "$work/v2/view_00.exr" "$work/local/view_00.exr"
echo "edge round trip ok"
