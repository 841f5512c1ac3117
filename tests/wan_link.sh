#!/usr/bin/env bash
# The emulated WAN link (testing/src/wan_link.cpp) between two network namespaces carries TCP with
# the delay, rate, loss and outages it is given: a connection takes one round trip (100 ms at
# 50 ms each way), 250 kB take about 2 s at 1 Mbit/s, a transfer completes through 3 % loss, and
# nothing passes while the link is down. Needs root (network namespaces): skipped otherwise.
set -euo pipefail
wan_link=$1
work=$2
if [ "$(id -u)" -ne 0 ] || ! command -v ip >/dev/null; then echo "needs root and iproute2: skipped"; exit 77; fi
rm -rf "$work"
mkdir -p "$work"
a=pcwa$$ b=pcwb$$
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  ip netns del "$a" 2>/dev/null || true
  ip netns del "$b" 2>/dev/null || true
}
trap cleanup EXIT
ip netns add "$a"
ip netns add "$b"
py=/usr/bin/python3
[ -x "$py" ] || py=python3
# A receiver in b: counts the bytes of each connection and answers one byte when it ends.
cat >"$work/sink.py" <<'PY'
import socket
s = socket.socket()
s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
s.bind(("10.88.0.2", 9000))
s.listen(8)
while True:
    c, _ = s.accept()
    n = 0
    while True:
        d = c.recv(65536)
        if not d:
            break
        n += len(d)
    c.sendall(b"k")
    c.close()
PY
# A sender in a: prints the connect time (ms) and the time (s) to send BYTES and hear back.
cat >"$work/send.py" <<'PY'
import socket, sys, time
size, timeout = int(sys.argv[1]), float(sys.argv[2])
t = time.time()
try:
    c = socket.create_connection(("10.88.0.2", 9000), timeout=timeout)
except OSError as e:
    print("unreachable", e)
    sys.exit(3)
connect = (time.time() - t) * 1000
t = time.time()
c.sendall(b"x" * size)
c.shutdown(socket.SHUT_WR)
assert c.recv(1) == b"k"
print("%.1f %.3f" % (connect, time.time() - t))
PY
start_link() {  # ARGS...
  "$wan_link" --ns-a "$a" --ns-b "$b" "$@" >"$work/link.log" 2>&1 &
  link=$!
  pids+=("$link")
  for _ in $(seq 50); do grep -q "wan_link: up" "$work/link.log" && return 0; sleep 0.1; done
  cat "$work/link.log"
  exit 1
}
ip netns exec "$b" "$py" "$work/sink.py" &
sink=$!
pids+=("$sink")

start_link --delay-ms 50 --rate-kbit 1000 --queue-bytes 65536
sleep 0.5  # the sink binds once its end of the link is up
read -r connect transfer < <(ip netns exec "$a" "$py" "$work/send.py" 250000 5)
echo "50 ms, 1 Mbit/s: connect $connect ms, 250 kB in $transfer s"
awk -v c="$connect" -v t="$transfer" 'BEGIN { exit !(c >= 100 && c < 200 && t >= 1.9 && t < 4.0) }' || {
  echo "the link does not carry the delay and rate it was given"; exit 1; }

# Down: nothing connects; up again: it does.
kill -USR1 "$link"
if ip netns exec "$a" "$py" "$work/send.py" 1000 1 >"$work/down.log"; then echo "a connection crossed a link that is down"; exit 1; fi
grep -q unreachable "$work/down.log"
kill -USR2 "$link"
ip netns exec "$a" "$py" "$work/send.py" 1000 5 >/dev/null
echo "outage: nothing crossed while down, connections again once up"
kill "$link"
wait "$link" 2>/dev/null || true

start_link --delay-ms 10 --loss 0.03 --rate-kbit 5000 --seed 7
read -r connect transfer < <(ip netns exec "$a" "$py" "$work/send.py" 250000 10)
kill "$link"
wait "$link" 2>/dev/null || true
grep -Eo "a->b [0-9]+ passed, [0-9]+ lost" "$work/link.log" | tee "$work/loss.txt"
lost=$(grep -Eo "[0-9]+ lost" "$work/loss.txt" | grep -Eo "[0-9]+")
[ "$lost" -gt 0 ] || { echo "3 % loss lost nothing"; exit 1; }
echo "3 % loss: 250 kB in $transfer s, every byte delivered"
echo "wan link ok"
