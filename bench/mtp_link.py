#!/usr/bin/env python3
"""The link phase of bench/motion_to_photon.py: over one emulated profile (two network namespaces
joined by wan_link, as bench/wan_bench.py sets them up), a head pose sent up at 90 Hz and video
frames of given sizes sent down at the display rate, both over TCP, each timed from its send to its
arrival (one machine, one clock); then a probe stream (`probecast serve` -> `probecast subscribe`)
over the same link for the lighting's age. Run as a script, it is one end of the pose/frame
traffic inside a namespace:

  mtp_link.py server --seconds S --fps F --sizes FILE --out FILE   (in the first namespace)
  mtp_link.py client --seconds S --out FILE                         (in the second)
"""
import argparse
import json
import os
import shutil
import socket
import struct
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from wan_bench import Run, percentile  # noqa: E402

PORT = 9100
POSE = struct.Struct("<dI28x")  # 40 bytes: send time, sequence, a pose's 28 (position, orientation)
FRAME = struct.Struct("<dI")     # send time, payload bytes
SETTLE_S = 1.0                    # the first second (TCP's slow start) is left out


def has_ip():
    return shutil.which("ip") is not None


def read_exactly(sock, n):
    buf = bytearray()
    while len(buf) < n:
        d = sock.recv(n - len(buf))
        if not d:
            return None
        buf += d
    return bytes(buf)


def server(a):
    """Accepts the client, records each pose's trip up, and sends the frames down at the rate."""
    sizes = json.load(open(a.sizes))
    lsock = socket.socket()
    lsock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    lsock.bind(("10.88.0.1", PORT))
    lsock.listen(1)
    print("listening", flush=True)
    conn, _ = lsock.accept()
    conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    up = []
    def poses():
        while True:
            m = read_exactly(conn, POSE.size)
            if m is None:
                return
            up.append((time.time(), time.time() - POSE.unpack(m)[0]))
    t = threading.Thread(target=poses, daemon=True)
    t.start()
    start = time.time()
    i = 0
    while time.time() - start < a.seconds:
        due = start + i / a.fps
        time.sleep(max(0.0, due - time.time()))
        n = sizes[i % len(sizes)]
        # Stamped when it is due (made): time spent behind earlier frames on a slow link counts.
        conn.sendall(FRAME.pack(due, n) + os.urandom(n))
        i += 1
    conn.shutdown(socket.SHUT_WR)
    t.join(timeout=a.seconds + 30)
    json.dump({"pose_up_ms": [1000 * d for at, d in up if at - start >= SETTLE_S], "frames_sent": i}, open(a.out, "w"))


def client(a):
    """Connects, sends poses at 90 Hz, and records each frame's trip down."""
    sock = None
    for _ in range(100):
        try:
            sock = socket.create_connection(("10.88.0.1", PORT), timeout=5)
            break
        except OSError:
            time.sleep(0.1)
    if sock is None:
        sys.exit("mtp_link client: cannot connect to 10.88.0.1:%d through the link" % PORT)
    sock.settimeout(None)
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    stop = threading.Event()
    def poses():
        k = 0
        while not stop.is_set():
            sock.sendall(POSE.pack(time.time(), k))
            k += 1
            time.sleep(1 / 90)
    threading.Thread(target=poses, daemon=True).start()
    start = time.time()
    down, arrivals = [], []
    while True:
        h = read_exactly(sock, FRAME.size)
        if h is None:
            break
        sent, n = FRAME.unpack(h)
        if read_exactly(sock, n) is None:
            break
        now = time.time()
        if now - start >= SETTLE_S:
            down.append(1000 * (now - sent))
            arrivals.append(now)
    stop.set()
    json.dump({"frame_down_ms": down, "arrivals": arrivals}, open(a.out, "w"))


def traffic(r, a, work, sizes, fps):
    """The pose and frame traffic through the link: (pose up ms, frame down ms, frames late)."""
    with open(os.path.join(work, "sizes.json"), "w") as f:
        json.dump(sizes, f)
    me = os.path.abspath(__file__)
    srv_out, cli_out = os.path.join(work, "mtp-server.json"), os.path.join(work, "mtp-client.json")
    srv = r.spawn(r.ns_a, [sys.executable, me, "server", "--seconds", str(a.seconds), "--fps", str(fps),
                           "--sizes", os.path.join(work, "sizes.json"), "--out", srv_out], "mtp-server.log")
    r.wait_for("mtp-server.log", "listening", 10)
    cli = r.spawn(r.ns_b, [sys.executable, me, "client", "--seconds", str(a.seconds), "--out", cli_out], "mtp-client.log")
    cli.wait(timeout=a.seconds + 120)
    srv.wait(timeout=60)
    up, down = json.load(open(srv_out))["pose_up_ms"], json.load(open(cli_out))
    # A frame is late when it arrives more than a frame's time after the one before.
    gaps = [b - a_ for a_, b in zip(down["arrivals"], down["arrivals"][1:])]
    return up, down["frame_down_ms"], sum(1 for g in gaps if g > 1.5 / fps)


def lighting_age(r, a, work):
    """The probe stream's produce -> receive latency over the link while its light moves (ms)."""
    token = os.path.join(work, "token")
    with open(token, "w") as f:
        f.write("mtp-%d\n" % os.getpid())
    r.spawn(r.ns_a, [a.probecast, "serve", "--scene", a.scene, "--grid", "8,8,8", "--repr", "zh3", "--hz", "10",
                     "--spp", "32", "--animate", "0.25", "--listen", "10.88.0.1:50051", "--plaintext", "--token-file", token,
                     "--seconds", str(a.seconds + 60)], "mtp-serve.log")
    r.wait_for("mtp-serve.log", "on port", 120)
    out = os.path.join(work, "mtp-subscribe.json")
    sub = r.spawn(r.ns_b, [a.probecast, "subscribe", "--connect", "10.88.0.1:50051", "--token-file", token,
                           "--seconds", str(a.seconds), "--json", out], "mtp-subscribe.log")
    sub.wait(timeout=a.seconds + 60)
    j = json.load(open(out))
    frames = [dict(zip(j["frame_fields"], f)) for f in j["frames"]]
    first = frames[0]["applied_us"] if frames else 0
    return [f["latency_us"] / 1e3 for f in frames if f["applied_us"] - first >= 3e6]  # after the first volume


def measure(a, work, profile, size_lists, fps):
    """One profile: each point's traffic, then the probe stream, over one emulated link; a link
    figure per point (the lighting's age is the same for all)."""
    from motion_to_photon import log
    folder = os.path.join(work, "link-" + profile)
    os.makedirs(folder, exist_ok=True)
    with Run(a, folder, profile, "direct", True) as r:
        traffics = [traffic(r, a, folder, sizes, fps) for sizes in size_lists]
        age = lighting_age(r, a, folder)
    if not age:
        raise RuntimeError("%s: the subscriber applied no frame after its first 3 s (see %s)" % (profile, folder))
    if not all(up and down for up, down, _ in traffics):
        raise RuntimeError("%s: no pose or no frame crossed the link after its first second (see %s)" % (profile, folder))
    out = []
    for up, down, late in traffics:
        log("%s: pose up %.1f ms, frame down %.1f ms (p99 %.1f), %d frames late, lighting %.0f ms old"
            % (profile, percentile(up, 0.5), percentile(down, 0.5), percentile(down, 0.99), late, percentile(age, 0.5)))
        out.append({"pose_up_ms": up, "frame_down_ms": down, "frames_late": late,
                    "lighting_age_p50": percentile(age, 0.5), "lighting_age_p99": percentile(age, 0.99)})
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("role", choices=["server", "client"])
    p.add_argument("--seconds", type=float, required=True)
    p.add_argument("--fps", type=float, default=30)
    p.add_argument("--sizes")
    p.add_argument("--out", required=True)
    a = p.parse_args()
    (server if a.role == "server" else client)(a)


if __name__ == "__main__":
    main()
