#!/usr/bin/env bash
# One attack of the hostile server (tests/hostile_server.cpp) on a viewer: a real `serve` of baked
# probes, the hostile server relaying it, and `view` or `subscribe` against the hostile one under
# strace in a folder of its own. The viewer must end in time with the exit code and message the
# attack calls for, never open a decoy (files outside the package a server could name), and write
# nothing outside its work folder.
#   cli_hostile.sh PROBECAST HOSTILE_SERVER BASE ATTACK   (BASE/v.pcpv from the fixture: ATTACK setup)
set -euo pipefail
probecast=$1
hostile=$2
base=$3
attack=$4
work=$base/$attack
if [ "$attack" = setup ]; then  # the fixture: the probes every attack's serve relays
  mkdir -p "$base"
  exec "$probecast" bake --scene builtin:cornell --grid 4,4,4 --spp 8 --updates 1 --out "$base/v.pcpv"
fi
rm -rf "$work"
mkdir -p "$work/cwd" "$work/home" "$work/cache"
fail() { echo "FAIL ($attack): $*"; exit 1; }
command -v strace >/dev/null || fail "strace is not installed (scripts/setup.sh installs it)"

pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done; wait 2>/dev/null || true; }
trap cleanup EXIT
# Waits up to 20 s for PATTERN in FILE.
await() { for _ in $(seq 200); do grep -q "$2" "$1" 2>/dev/null && return 0; sleep 0.1; done; fail "no '$2' in $1: $(cat "$1")"; }

up=$((20000 + RANDOM % 20000))
port=$((up + 1))
"$probecast" serve --probes "$base/v.pcpv" --listen "127.0.0.1:$up" --token t --plaintext --seconds 100 \
  >"$work/serve.log" 2>&1 &
pids+=($!)
await "$work/serve.log" "on port $up"
"$hostile" "127.0.0.1:$up" "127.0.0.1:$port" t "$attack" "$work/cwd" >"$work/hostile.log" 2>&1 &
pids+=($!)
await "$work/hostile.log" "hostile: listening"

view=(view --connect "127.0.0.1:$port" --token t --views mono --size 32x24 --wait 2 --visibility off
      --out "$work/out")
subscribe=(subscribe --connect "127.0.0.1:$port" --token t --seconds 2 --out "$work/sub.pcpv")
# attack → client, exit code, message (an extended regular expression)
case $attack in
  none) cmd=("${view[@]}") code=0 say="frames \([0-9]+ bytes\) from" ;;
  gltf-dotdot|gltf-percent|image-dotdot) cmd=("${view[@]}") code=1 say="refused to read '.*' leaves the glTF's folder" ;;
  gltf-absolute) cmd=("${view[@]}") code=1 say="refused to read '.*' (is absolute|leaves the glTF's folder|is not inside)" ;;
  gltf-file-uri) cmd=("${view[@]}") code=1 say="refused to read '.*' names a URI scheme" ;;
  gltf-unlisted|image-unlisted) cmd=("${view[@]}") code=1 say="refused to read '.*decoy.*' is not a file of the scene's package" ;;
  size-overflow) cmd=("${view[@]}" --scene-max-bytes 1000000) code=1 say="manifest files add up to more than" ;;
  noncanonical) cmd=("${view[@]}") code=1 say="not canonical JSON" ;;
  bad-utf8) cmd=(subscribe --connect "127.0.0.1:$port" --token t --seconds 4 --out "$work/sub.pcpv") code=1 say="refused: .*broke off without an end \(a message that does not parse\)" ;;
  scene-switch) cmd=("${view[@]}") code=1 say="the stream names scene [0-9a-f]+, not the scene [0-9a-f]+" ;;
  scene-stall) cmd=("${view[@]}") code=1 say="it sent nothing for 15000 ms" ;;
  garbage-frames|huge-frames) cmd=("${view[@]}") code=1 say="refused: frame refused: its payload is no frame" ;;
  nan-time|nan-lights) cmd=("${view[@]}") code=1 say="refused: frame refused: " ;;
  counts) cmd=("${view[@]}") code=1 say="it claims 4294967295 keyframes and 4294967295 deltas" ;;
  huge-grid) cmd=("${subscribe[@]}") code=1 say="holds 16777216 probes, more than the 2097152 this client accepts" ;;
  escape-text) cmd=("${subscribe[@]}") code=1 say='upstream failed \\x1b\]0;owned\\x07\\x1b\[2J' ;;
  *) fail "unknown attack" ;;
esac

rc=0
(cd "$work/cwd" && HOME="$work/home" XDG_CACHE_HOME="$work/home/.cache" PROBECAST_SCENE_CACHE="$work/cache" \
  MESA_SHADER_CACHE_DISABLE=true TMPDIR="$work/home" timeout 60 strace -f -qq -o "$work/trace" \
  -e trace=open,openat,openat2,creat,mkdir,mkdirat,rename,renameat,renameat2,unlink,unlinkat,symlink,symlinkat,link,linkat,truncate \
  "$probecast" "${cmd[@]}") >"$work/out.log" 2>&1 || rc=$?
[ "$rc" -ne 124 ] || fail "the viewer did not end within 60 s: $(tail -5 "$work/out.log")"
[ "$rc" -eq "$code" ] || fail "exit code $rc, expected $code: $(tail -8 "$work/out.log")"
grep -Eq "$say" "$work/out.log" || fail "no /$say/ in: $(tail -8 "$work/out.log")"
if LC_ALL=C grep -q $'\x1b' "$work/out.log"; then fail "an escape byte from the wire reached the terminal"; fi

# The filesystem: no decoy opened (they sit in the working folder and are named by absolute and
# relative paths), nothing made, renamed or removed outside the work folder (devices aside). A
# relative name is inside it: the working folder is, and *at calls name folders opened inside it.
! grep -q "decoy" "$work/trace" || fail "a decoy was opened: $(grep decoy "$work/trace" | head -3)"
outside=$(grep -E 'O_WRONLY|O_RDWR|O_CREAT|creat\(|mkdir|rename|unlink|symlink|link\(|truncate' "$work/trace" |
  grep -v ' = -1 ' | grep -oE '"/[^"]*"' | tr -d '"' | grep -vE "^($work|/dev/|/proc/self/)" | sort -u || true)
[ -z "$outside" ] || fail "written outside the work folder: $outside"
cached=$(du -sb "$work/cache" | cut -f1)
[ "$cached" -lt 1000000 ] || fail "the scene cache holds $cached bytes"
# Sizes that wrap: refused before the first byte is asked for.
if [ "$attack" = size-overflow ] && grep -q "GetScene asked" "$work/hostile.log"; then
  fail "the viewer asked for a scene whose sizes wrap around"
fi
if [ "$code" -ne 0 ]; then
  [ ! -e "$work/sub.pcpv" ] || fail "a volume was written although the client refused the stream"
  [ ! -e "$work/out/quilt.png" ] || fail "a picture was drawn although the viewer refused the stream"
fi
echo "hostile $attack ok"
