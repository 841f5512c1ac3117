#!/usr/bin/env bash
# `view --head-trace T --frames N --fps F` without a window: N pictures along a recorded head's
# motion or a scripted camera path, from one set of probes. The same trace gives the same pictures
# byte for byte; the camera moves between them; what cannot go with it is refused by name.
set -euo pipefail
probecast=$1
work=$2
rm -rf "$work"
mkdir -p "$work"
cd "$work"
fail() { echo "FAILED: $*"; exit 1; }
"$probecast" -q bake --scene builtin:cornell --grid 4,4,4 --spp 8 --updates 1 --out p.pcpv >/dev/null
run() { "$probecast" -q view --scene builtin:cornell --probes p.pcpv --views stereo --size 48x32 --frames 5 --fps 2 "$@"; }
run --head-trace builtin:mmsys18-user1 --out a >a.log
run --head-trace builtin:mmsys18-user1 --out b >/dev/null
[ "$(ls a/frame_*.png | wc -l)" -eq 5 ] || fail "5 pictures expected, got $(ls a | tr '\n' ' ')"
grep -q "5 frames along builtin:mmsys18-user1 (2.00 s at 2 a second)" a.log || fail "no summary line: $(cat a.log)"
for f in a/frame_*.png; do cmp -s "$f" "b/$(basename "$f")" || fail "$f differs between two runs of the same trace"; done
cmp -s a/frame_0000.png a/frame_0004.png && fail "the head did not move the camera in 2 s"
run --head-trace builtin:walk-1m --out w >/dev/null
cmp -s w/frame_0000.png w/frame_0004.png && fail "the walk did not move the camera"
cmp -s w/frame_0002.png a/frame_0002.png && fail "the walk and the head gave the same picture"
printf 'probecast-camera-path 1\n0 0 0 0 0 0\n1 0 0 0 0 95\n' >bad.txt
if out=$(run --head-trace bad.txt --out x 2>&1); then fail "a pitch beyond 90 degrees was accepted"; fi
grep -q "bad.txt: line 3: a pitch beyond" <<<"$out" || fail "the bad path's line was not named: $out"
if out=$(run --head-trace builtin:walk-1m --connect 127.0.0.1:1 --token t --out x 2>&1); then fail "--connect accepted"; fi
grep -q "draws local probes" <<<"$out" || fail "--connect not refused by name: $out"
echo "view sequence ok"
