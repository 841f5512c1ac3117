#!/usr/bin/env python3
"""Streams probes over emulated wide-area links and measures what a subscriber gets.

Two network namespaces joined by wan_link (testing/src/wan_link.cpp: delay, loss, a rate with a
drop-tail queue, outages). On one side a live `probecast serve` (and, for the bus path, a
nats-server and a `probecast edge`); on the other, subscribers: one from the start, a late joiner,
and a ten-second outage in the middle. Then the lighting is held and every subscriber must end
with the server's volume, bit for bit (its checksum).

Per profile and path (direct, or through NATS and an edge) it reports delivered bytes per second,
produce → receive latency (p50, p99) while the light moves, the late joiner's time to a usable
volume (every brick held), the time from the link's return to the next frame, whether every
subscriber settled on the server's volume, and how far the first subscriber's picture is from a
perfect link's: a subscriber beside the server (no emulated link) and the first one write the volume
they hold at the same instants (subscribe --snapshot-every), each pair is drawn by `probecast view`
and compared (PSNR while the light moves, while the link is out, and after it returns). JSON on stdout (or --json) and an SVG chart (--svg).

Needs root (network namespaces), iproute2, and for the bus path nats-server.

  sudo bench/wan_bench.py --probecast build/probecast --wan-link build/testing/wan_link \\
      --json wan.json --svg wan.svg
  bench/wan_bench.py ... --test     short run of one slow profile, paced and unpaced, with assertions
"""
import argparse
import json
import math
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

PROFILES = {  # the three, and a lossless slow one for the test
    # name: (one-way delay ms, loss, rate kbit/s, bottleneck queue bytes)
    "lan-20ms-50mbit": (10.0, 0.0, 50000.0, 256 * 1024),
    "wan-100ms-1pct-5mbit": (50.0, 0.01, 5000.0, 128 * 1024),
    "mobile-250ms-3pct-1mbit": (125.0, 0.03, 1000.0, 64 * 1024),
    "slow-100ms-1mbit": (50.0, 0.0, 1000.0, 64 * 1024),
}


def log(*a):
    print("wan_bench:", *a, file=sys.stderr, flush=True)


class Bed:
    """Two network namespaces joined by the emulated link, and the processes started in them."""

    def __init__(self, args, work, profile):
        self.args, self.work, self.profile = args, work, profile
        tag = "%d%d" % (os.getpid() % 10000, int(time.time() * 10) % 1000)
        self.ns_a, self.ns_b = "pcba" + tag, "pcbb" + tag
        self.procs = []
        self.link = None

    def spawn(self, ns, argv, log_name):
        out = open(os.path.join(self.work, log_name), "w")
        cmd = ["ip", "netns", "exec", ns] + argv if ns else argv
        p = subprocess.Popen(cmd, stdout=out, stderr=subprocess.STDOUT)
        self.procs.append(p)
        return p

    def wait_for(self, log_name, text, seconds):
        path = os.path.join(self.work, log_name)
        end = time.time() + seconds
        while time.time() < end:
            try:
                if text in open(path).read():
                    return True
            except FileNotFoundError:
                pass
            time.sleep(0.05)
        raise RuntimeError("%s did not say '%s' within %.0f s:\n%s" % (log_name, text, seconds, open(path).read()[-2000:]))

    def __enter__(self):
        for ns in (self.ns_a, self.ns_b):
            subprocess.run(["ip", "netns", "add", ns], check=True)
            subprocess.run(["ip", "netns", "exec", ns, "ip", "link", "set", "lo", "up"], check=True)
        delay, loss, rate, queue = PROFILES[self.profile]
        self.link = self.spawn(None, [self.args.wan_link, "--ns-a", self.ns_a, "--ns-b", self.ns_b, "--delay-ms", str(delay),
                                      "--loss", str(loss), "--rate-kbit", str(rate), "--queue-bytes", str(queue),
                                      "--seed", "7"], "link.log")
        self.wait_for("link.log", "wan_link: up", 10)
        return self

    def __exit__(self, *exc):
        for p in reversed(self.procs):
            if p.poll() is None:
                p.send_signal(signal.SIGTERM)
        for p in reversed(self.procs):
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
        for ns in (self.ns_a, self.ns_b):
            subprocess.run(["ip", "netns", "del", ns], stderr=subprocess.DEVNULL)

    # nats-server with JetStream and a token; the token's file.
    def start_bus(self):
        nats = shutil.which("nats-server") or "/usr/sbin/nats-server"
        bus_token = os.path.join(self.work, "bus-token")
        with open(bus_token, "w") as f:
            f.write("bus-%d\n" % os.getpid())
        with open(os.path.join(self.work, "nats.conf"), "w") as f:
            f.write('authorization { token: "bus-%d" }\n' % os.getpid())
        self.spawn(self.ns_a, [nats, "-c", os.path.join(self.work, "nats.conf"), "-a", "127.0.0.1", "-p", "4222", "-js",
                               "-sd", os.path.join(self.work, "nats")], "nats.log")
        self.wait_for("nats.log", "Server is ready", 10)
        return bus_token

    # The link goes down and comes back at the timeline's times; when it did.
    def cut_link(self, start, span):
        time.sleep(max(0.0, start + span[0] - time.time()))
        self.link.send_signal(signal.SIGUSR1)
        down = time.time()
        time.sleep(max(0.0, start + span[1] - time.time()))
        self.link.send_signal(signal.SIGUSR2)
        return (down, time.time())


class Run(Bed):
    """One profile on one path: the server side, the subscribers, the outage, their results."""

    def __init__(self, args, work, profile, path, pacing):
        super().__init__(args, work, profile)
        self.path, self.pacing = path, pacing
        self.token = os.path.join(work, "token")

    def go(self):
        T = self.args.timeline
        t0, address = self.start_server()
        start = time.time()  # the timeline's 0: the server is up
        subs = [self.subscriber("reference", self.ns_a, start, T["first"], address),
                self.subscriber("first", self.ns_b, start, T["first"], address),
                self.subscriber("late", self.ns_b, start, T["late"], address)]
        outage = self.cut_link(start, T["outage"]) if T.get("outage") else None
        for _, _, p in subs:
            p.wait(timeout=T["end"] + 60)
        return self.results(subs, t0, start, outage)

    # serve (and, for the bus path, nats-server and an edge) in the first namespace; when serve
    # began, and the address subscribers connect to.
    def start_server(self):
        a, T = self.args, self.args.timeline
        with open(self.token, "w") as f:
            f.write("wan-%d\n" % os.getpid())
        pacing = ["--link-pacing", "on" if self.pacing else "off"]
        serve = [a.probecast, "serve", "--scene", a.scene, "--grid", a.grid, "--repr", a.repr, "--hz", str(a.hz),
                 "--spp", str(a.spp), "--bounces", str(a.bounces),
                 "--animate", str(a.animate), "--noise-scale", "0", "--deadzone", "0", "--listen", "10.88.0.1:50051",
                 "--plaintext", "--token-file", self.token, "--hold-after", str(T["hold"]), "--seconds", str(T["end"] + 15)] + pacing
        if self.path != "edge":
            t0 = time.time()
            self.spawn(self.ns_a, serve, "serve.log")
            self.wait_for("serve.log", "on port", 120)
            return t0, "10.88.0.1:50051"
        bus_token = self.start_bus()
        t0 = time.time()
        self.spawn(self.ns_a, serve + ["--publish", "nats://127.0.0.1:4222", "--stream", "wan", "--nats-token-file",
                                       bus_token, "--nats-plaintext"], "serve.log")
        self.wait_for("serve.log", "on port", 120)
        self.spawn(self.ns_a, [a.probecast, "edge", "--nats", "nats://127.0.0.1:4222", "--stream", "wan",
                               "--nats-token-file", bus_token, "--nats-plaintext",
                               "--listen", "10.88.0.1:50052", "--plaintext", "--token-file", self.token,
                               "--seconds", str(T["end"] + 15)] + pacing, "edge.log")
        self.wait_for("edge.log", "on port", 30)
        return t0, "10.88.0.1:50052"

    # `probecast subscribe` in namespace `ns` from `at` s after `start` to the timeline's end.
    def subscriber(self, name, ns, start, at, addr):
        a, until = self.args, self.args.timeline["end"]
        delay = start + at - time.time()
        if delay > 0:
            time.sleep(delay)
        argv = [a.probecast, "subscribe", "--connect", addr, "--token-file", self.token, "--seconds", str(until - at),
                "--json", os.path.join(self.work, name + ".json")]
        if a.gap_period > 0 and name in ("reference", "first"):  # their pictures are compared afterwards
            argv += ["--snapshot-every", str(a.gap_period), "--snapshot-dir", os.path.join(self.work, name + "-snapshots")]
        return (name, time.time(), self.spawn(ns, argv, name + ".log"))

    def results(self, subs, t0, start, outage):
        serve_log = open(os.path.join(self.work, "serve.log")).read()
        held = [l for l in serve_log.splitlines() if "holding the lighting" in l]
        server_checksum = held[0].rsplit(" ", 1)[1] if held else None
        out = {"profile": self.profile, "path": self.path, "link_pacing": self.pacing,
               "link": dict(zip(["delay_ms", "loss", "rate_kbit", "queue_bytes"], PROFILES[self.profile])),
               "server_checksum": server_checksum, "setup_s": round(start - t0, 2)}
        loaded = {}
        for name, began, p in subs:
            with open(os.path.join(self.work, name + ".json")) as f:
                loaded[name] = (json.load(f), began, p.returncode)
        # A usable volume: as many bricks as the perfect link's subscriber ends with (bricks whose
        # probes are all inactive are never sent).
        ref = loaded["reference"][0]["frames"]
        T = dict(self.args.timeline, bricks=ref[-1][5] if ref else 0)
        for name, (j, began, rc) in loaded.items():
            out[name] = summarise(j, began, start, T, outage, server_checksum, rc)
        if self.args.gap_period > 0:
            out["first"]["picture_gap"] = picture_gap(self.args, self.work, T, start, t0, outage)
        return out


def picture_gap(a, work, T, start, t0, outage):
    """The first subscriber's picture against the perfect link's (the reference subscriber beside
    the server), from the volumes both held at the same instants: each pair is drawn by `probecast
    view` (same views, same scene time, so only the probes differ) and compared. PSNR from the
    mean squared error pooled over the instants of each phase: while the light moves, while the
    link is out, and from 2 s after its return until the lighting holds; and the worst instant."""
    ref_dir, sub_dir = os.path.join(work, "reference-snapshots"), os.path.join(work, "first-snapshots")
    def held(folder):  # none when the subscriber never held a volume
        return set(f for f in os.listdir(folder) if f.endswith(".pcpv")) if os.path.isdir(folder) else set()

    ticks = sorted(held(ref_dir) & held(sub_dir))
    views, size = a.gap_views.split("@")
    phases = {"moving": (T["steady"][0], T["steady"][1]), "outage": None, "after_outage": None}
    if outage:
        phases["outage"] = (outage[0] - start, outage[1] - start)
        phases["after_outage"] = (outage[1] - start + 2.0, T["hold"])
    sums = {k: [0.0, 0] for k in phases}
    worst = None
    render = os.path.join(work, "gap-render")
    for name in ticks:
        at = int(name[:-5]) * a.gap_period - start  # the instant on the timeline
        if not T["steady"][0] <= at < T["hold"]:
            continue
        scene_time = max(0.0, (int(name[:-5]) * a.gap_period - t0) * a.animate)
        images = []
        for side, folder in (("reference", ref_dir), ("first", sub_dir)):
            out = os.path.join(render, side)
            subprocess.run([a.probecast, "-q", "view", "--scene", a.scene, "--time", "%.4f" % scene_time, "--probes",
                            os.path.join(folder, name), "--views", views, "--size", size, "--visibility", "off",
                            "--out", out], check=True, stdout=subprocess.DEVNULL)
            images.append(os.path.join(out, "quilt.exr"))
        metrics = os.path.join(render, "compare.json")
        subprocess.run([a.probecast, "-q", "compare", images[1], images[0], "--json", metrics], check=True,
                       stdout=subprocess.DEVNULL)
        with open(metrics) as f:
            m = json.load(f)
        if worst is None or m["mse"] > worst[0]:
            worst = (m["mse"], m["psnr_db"], round(at, 1))
        for k, span in phases.items():
            if span and span[0] <= at < span[1]:
                sums[k][0] += m["mse"]
                sums[k][1] += 1
    shutil.rmtree(render, ignore_errors=True)
    peak = 1.0  # compare's images after gamma: PSNR = 10 log10(1 / MSE)

    def pooled(k):
        total, n = sums[k]
        if n == 0:
            return None
        return round(10 * math.log10(peak / (total / n)), 1) if total > 0 else "identical"

    gap = {"views": a.gap_views, "period_s": a.gap_period, "instants": sum(n for _, n in sums.values())}
    for k in phases:
        gap[k + "_psnr_db"] = pooled(k)
        gap[k + "_instants"] = sums[k][1]
    if worst:
        gap["worst_psnr_db"], gap["worst_at_s"] = round(worst[1], 1), worst[2]
    return gap


def percentile(values, p):
    if not values:
        return None
    v = sorted(values)
    return v[min(len(v) - 1, int(round(p * (len(v) - 1))))]


def summarise(j, began, start, T, outage, server_checksum, rc):
    fields = j["frame_fields"]
    frames = [dict(zip(fields, f)) for f in j["frames"]]
    for f in frames:
        f["t"] = f["applied_us"] / 1e6 - start
    moving = [f for f in frames if T["steady"][0] <= f["t"] < T["steady"][1]]
    span = T["steady"][1] - T["steady"][0]
    s = {"exit": rc, "frames": len(frames), "bytes": j["bytes"], "connects": j["connects"],
         "silences": j.get("silences"), "bricks_held": frames[-1]["bricks_held"] if frames else 0,
         "settled": j["checksum"] == server_checksum, "checksum": j["checksum"],
         "steady_bytes_per_s": round(sum(f["bytes"] for f in moving) / span),
         "latency_p50_ms": None, "latency_p99_ms": None,
         "server_link": {k: j["server"][k] for k in ("link_rate", "link_min_rtt_us", "link_window", "link_waits")}}
    lat = [f["latency_us"] / 1e3 for f in moving]
    if lat:
        s["latency_p50_ms"] = round(percentile(lat, 0.5), 1)
        s["latency_p99_ms"] = round(percentile(lat, 0.99), 1)
    usable = [f for f in frames if f["bricks_held"] >= T["bricks"]]
    s["first_usable_s"] = round(usable[0]["applied_us"] / 1e6 - began, 3) if usable else None
    if outage:
        after = [f for f in frames if f["applied_us"] / 1e6 >= outage[1]]
        s["resume_s"] = round(after[0]["applied_us"] / 1e6 - outage[1], 3) if after else None
        # What came in the first five seconds back: keyframes (whole bricks) against deltas.
        back = [f for f in after if f["applied_us"] / 1e6 < outage[1] + 5]
        s["after_outage_keyframes"] = sum(f["keyframes"] for f in back)
        s["after_outage_deltas"] = sum(f["deltas"] for f in back)
        s["after_outage_bytes"] = sum(f["bytes"] for f in back)
        recent = [f["latency_us"] / 1e3 for f in after if outage[1] + 3 <= f["applied_us"] / 1e6 < outage[1] + 8]
        s["latency_p99_after_outage_ms"] = round(percentile(recent, 0.99), 1) if recent else None
    return s


def svg_chart(results, path):
    """Latency p99 and delivered rate per profile and path: two rows of bars."""
    rows = [r for r in results if "first" in r]
    w, bar, gap = 900, 26, 14
    h = 120 + len(rows) * (bar + gap)
    maxlat = max([r["first"]["latency_p99_ms"] or 0 for r in rows] + [1])
    out = ['<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" font-family="sans-serif" font-size="12">' % (w, h),
           '<rect width="100%" height="100%" fill="white"/>',
           '<text x="10" y="20" font-size="14">probecast over emulated links: produce → receive p99 while the light moves</text>']
    y = 50
    for r in rows:
        label = "%s, %s, pacing %s" % (r["profile"], r["path"], "on" if r["link_pacing"] else "off")
        p99 = r["first"]["latency_p99_ms"] or 0
        bw = 420 * p99 / maxlat
        colour = "#3b7dd8" if r["link_pacing"] else "#d8703b"
        out.append('<text x="10" y="%d">%s</text>' % (y + 17, label))
        out.append('<rect x="330" y="%d" width="%.1f" height="%d" fill="%s"/>' % (y, bw, bar, colour))
        out.append('<text x="%.1f" y="%d">%.0f ms p99, %.0f kB/s%s</text>' % (
            336 + bw, y + 17, p99, r["first"]["steady_bytes_per_s"] / 1e3,
            ", settled" if r["first"]["settled"] and r["late"]["settled"] else ", NOT SETTLED"))
        y += bar + gap
    out.append('<text x="10" y="%d" fill="#555">blue: link-aware pacing on; orange: off. Command: %s</text>' % (
        y + 20, " ".join(sys.argv).replace("&", "&amp;").replace("<", "&lt;")))
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--probecast", required=True)
    ap.add_argument("--wan-link", required=True)
    ap.add_argument("--work", default=None, help="folder for logs and subscriber JSON (default: a temporary one)")
    ap.add_argument("--profiles", default=",".join(PROFILES), help="comma-separated: " + ", ".join(PROFILES))
    ap.add_argument("--paths", default="direct,edge", help="direct, edge (NATS + an edge), or both")
    ap.add_argument("--pacing", default="on,off", help="link pacing on, off, or both")
    ap.add_argument("--scene", default="builtin:cornell")
    ap.add_argument("--grid", default="32,8,32")
    ap.add_argument("--repr", default="l2")
    ap.add_argument("--spp", type=int, default=8, help="paths per probe per update (few: noisy light, a heavy stream)")
    ap.add_argument("--bounces", type=int, default=2)
    ap.add_argument("--hz", type=float, default=10.0)
    ap.add_argument("--animate", type=float, default=0.2, help="scene seconds per second (the light moves)")
    ap.add_argument("--gap-period", type=float, default=1.0,
                    help="seconds between the instants at which the first subscriber's picture is set against the perfect "
                         "link's (0: not measured)")
    ap.add_argument("--gap-views", default="stereo@96x96", help="views drawn for that comparison, VIEWSET@WxH")
    ap.add_argument("--json", default=None)
    ap.add_argument("--svg", default=None)
    ap.add_argument("--test", action="store_true", help="a short run with assertions (ctest net.wan_pacing)")
    args = ap.parse_args()
    if os.geteuid() != 0 or not shutil.which("ip"):
        print("needs root and iproute2: skipped")
        return 77
    if args.test:
        args.profiles, args.paths, args.pacing = "slow-100ms-1mbit", "direct", "on,off"
        timeline = {"first": 0.0, "late": 6.0, "steady": (3.0, 12.0), "outage": (12.0, 16.0), "hold": 18.0, "end": 24.0}
    else:
        timeline = {"first": 0.0, "late": 10.0, "steady": (4.0, 16.0), "outage": (16.0, 26.0), "hold": 34.0, "end": 44.0}
    args.timeline = timeline
    work = args.work or tempfile.mkdtemp(prefix="probecast-wan-")
    results = []
    for profile in args.profiles.split(","):
        if profile not in PROFILES:
            print("unknown profile %s (known: %s)" % (profile, ", ".join(PROFILES)), file=sys.stderr)
            return 2
        for path in args.paths.split(","):
            for pacing in args.pacing.split(","):
                d = os.path.join(work, "%s-%s-%s" % (profile, path, pacing))
                shutil.rmtree(d, ignore_errors=True)
                os.makedirs(d)
                log("%s, %s, pacing %s (logs in %s)" % (profile, path, pacing, d))
                with Run(args, d, profile, path, pacing == "on") as run:
                    r = run.go()
                results.append(r)
                f = r["first"]
                g = f.get("picture_gap", {})
                log("  %s kB/s, p50 %s ms, p99 %s ms, late joiner usable in %s s, resume %s s, settled %s/%s/%s, "
                    "picture against a perfect link %s dB moving, %s dB after the outage" % (
                        round(f["steady_bytes_per_s"] / 1e3, 1), f["latency_p50_ms"], f["latency_p99_ms"],
                        r["late"]["first_usable_s"], f.get("resume_s"), r["reference"]["settled"], f["settled"],
                        r["late"]["settled"], g.get("moving_psnr_db"), g.get("after_outage_psnr_db")))
    report = {"command": " ".join(sys.argv), "timeline_s": timeline, "scene": args.scene, "grid": args.grid,
              "repr": args.repr, "spp": args.spp, "bounces": args.bounces, "hz": args.hz, "animate": args.animate, "results": results}
    text = json.dumps(report, indent=1)
    if args.json:
        with open(args.json, "w") as f:
            f.write(text + "\n")
    print(text)
    if args.svg:
        svg_chart(results, args.svg)
    if args.test:
        return check(results)
    return 0


def check(results):
    """What must hold: paced, the slow link's latency stays bounded, the picture keeps a PSNR of at
    least 25 dB against a perfect link's and is closer to it than unpaced, and nothing is lost; unpaced, the same
    stream's latency grows (the test can tell the two apart)."""
    failures = []
    by = {r["link_pacing"]: r for r in results}
    on, off = by[True], by[False]
    for r in results:
        for name in ("reference", "first", "late"):
            s = r[name]
            if s["exit"] != 0:
                failures.append("%s subscriber exited %d (pacing %s)" % (name, s["exit"], r["link_pacing"]))
    for name in ("reference", "first", "late"):
        if not on[name]["settled"]:
            failures.append("paced: the %s subscriber holds %s, the server %s" % (name, on[name]["checksum"],
                                                                                 on["server_checksum"]))
    f = on["first"]
    if f["latency_p99_ms"] is None or f["latency_p99_ms"] > 1500:
        failures.append("paced: p99 latency %s ms over a 1 Mbit/s, 100 ms link (bound 1500 ms)" % f["latency_p99_ms"])
    if f["steady_bytes_per_s"] < 0.5 * off["first"]["steady_bytes_per_s"]:
        failures.append("paced: %d B/s delivered, under half of the unpaced %d B/s" % (
            f["steady_bytes_per_s"], off["first"]["steady_bytes_per_s"]))
    rate = f["server_link"]["link_rate"]
    # The last estimate, from the connection made after the outage: within what the link carries
    # and no less than a third of what the unpaced stream got through it.
    if not off["first"]["steady_bytes_per_s"] / 3 <= rate <= 1.3 * 125000:
        failures.append("paced: the server estimates %d B/s for a 125 kB/s link" % rate)
    # The picture a subscriber draws while the light moves, against a perfect link's.
    gap_on = f.get("picture_gap", {}).get("moving_psnr_db")
    gap_off = off["first"].get("picture_gap", {}).get("moving_psnr_db")
    if gap_on is not None and gap_on != "identical":
        if gap_on < 25.0:
            failures.append("paced: the picture is %.1f dB from a perfect link's while the light moves (bound 25 dB)" % gap_on)
        if gap_off not in (None, "identical") and gap_on <= gap_off:
            failures.append("paced: the picture (%.1f dB from a perfect link's) is no closer than unpaced (%.1f dB)" %
                            (gap_on, gap_off))
    # Overlapping connection attempts meet the link's return within 125 ms; then the handshake,
    # HTTP/2's settings and the Hello take three 100 ms round trips, and the first frame 8 kB.
    if f.get("resume_s") is None or f["resume_s"] > 1.0:
        failures.append("paced: no frame within 1 s of the link's return (%s)" % f.get("resume_s"))
    if off["first"]["latency_p99_ms"] is not None and off["first"]["latency_p99_ms"] < 2 * f["latency_p99_ms"]:
        failures.append("unpaced p99 %s ms is not clearly worse than paced %s ms: the stream does not load the link" %
                        (off["first"]["latency_p99_ms"], f["latency_p99_ms"]))
    for m in failures:
        print("FAIL:", m)
    if not failures:
        print("wan_pacing: paced p99 %.0f ms (unpaced %.0f ms), %.1f kB/s, link estimate %.1f kB/s, resume %.2f s, "
              "picture %s dB from a perfect link's (unpaced %s dB), settled" %
              (f["latency_p99_ms"], off["first"]["latency_p99_ms"] or 0, f["steady_bytes_per_s"] / 1e3, rate / 1e3,
               f["resume_s"], gap_on, gap_off))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
