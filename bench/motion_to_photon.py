#!/usr/bin/env python3
"""Motion-to-photon of a headset, the probe client against video streaming, per emulated link.

The probe client draws every frame itself from the newest lighting it holds, so a head movement
reaches the display in one frame of its own drawing whatever the link; the lighting's age (the
stream's produce -> receive latency over the link) is a separate column. Video streaming has to
carry the pose to the server, draw the views there, encode them, carry the frame back and decode
it before the display shows the movement. Each component is measured here, not assumed:

  - drawing the stereo pair (the client's frame; the video server's render): `probecast bench
    raster --views stereo` on this machine's device;
  - encoding and decoding each codec's frames: ffmpeg with `bench video`'s low-latency settings on
    the frames `bench video` drew of the same head motion, at the point of equal quality with the
    stream (the cheapest point at least as close to the reference as the stream);
  - the link: for each profile, two network namespaces joined by wan_link (testing/src/wan_link.cpp,
    as bench/wan_bench.py), a pose sent up at 90 Hz and the encoded frames, at their real sizes,
    sent down at the display rate over TCP; and a `probecast serve` -> `probecast subscribe` over
    the same link for the lighting's age.

Video's pose-to-photon = pose up + render + encode + frame down + decode: the link terms' medians
(and, for the p99 column, their p99s) with the drawing's median and the codec's mean time a frame
over the whole run (ffmpeg's start included: throughput, which a frame's latency is at least).
JSON (--json) and an SVG chart (--svg).
Needs root (network namespaces), iproute2 and ffmpeg.

  sudo bench/motion_to_photon.py --probecast build/probecast --wan-link build/testing/wan_link \\
      --json mtp.json --svg mtp.svg
  bench/motion_to_photon.py ... --test     small frames, one profile, short runs, with assertions
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mtp_link  # noqa: E402  (the link phase: namespaces, pose and frame traffic)
from wan_bench import PROFILES, percentile  # noqa: E402


def log(*a):
    print("motion_to_photon:", *a, file=sys.stderr, flush=True)


def run(argv, what, **kw):
    r = subprocess.run(argv, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        raise RuntimeError("%s failed (%d): %s" % (what, r.returncode, (r.stderr or r.stdout)[-2000:]))
    return r.stdout + r.stderr


def video_frames(a, work):
    """bench video of the headset with the head trace (or the run --video-json names): its JSON,
    with the frames and bitstreams it kept."""
    if a.video_json:
        return json.load(open(a.video_json))
    out = os.path.join(work, "video.json")
    log("bench video: the headset at %s per eye, %s, %d frames (minutes)" % (a.size, a.head_trace, a.frames))
    run([a.probecast, "bench", "video", "--scene", a.scene, "--motions", "still=0", "--streams", a.streams,
         "--codecs", a.codecs, "--displays", "headset=stereo@" + a.size, "--x265-crf", a.x265_crf, "--av1-crf", a.av1_crf,
         "--frames", str(a.frames), "--warmup", str(a.warmup), "--head-trace", a.head_trace, "--work-dir", work,
         "--keep-files", "--json", out], "bench video")
    return json.load(open(out))


def equal_quality_points(video):
    """Per stream and codec, the cheapest video point at least as close to the reference as the
    stream (or the closest point when none is), with its bitstream and encode time a frame."""
    points = []
    for r in video["results"]:
        if r["view_set"] != "stereo":
            continue  # the headset's run (a --video-json may hold other displays too)
        for s in r["streams"]:
            for v in r["video"]:
                # "identical": a point equal to the reference frame for frame, as close as any.
                sweep = [dict(p, psnr_db=float("inf") if p["psnr_db"] == "identical" else p["psnr_db"]) for p in v["sweep"]]
                stream_db = float("inf") if s["psnr_db"] == "identical" else s["psnr_db"]
                good = [p for p in sweep if p["psnr_db"] >= stream_db]
                p = min(good, key=lambda q: q["bytes_per_second"]) if good else max(sweep, key=lambda q: q["psnr_db"])
                ext = "hevc" if v["encoder"] == "libx265" else "obu"
                bitstream = os.path.join(video["kept_files"], "%s-%s-%s-crf%d.%s" % (r["motion"], r["display"], v["codec"], p["crf"], ext))
                points.append({"stream": s["stream"], "stream_bytes_per_second": s["bytes_per_second"],
                               "stream_psnr_db": s["psnr_db"], "codec": v["codec"], "crf": p["crf"],
                               "video_bytes_per_second": p["bytes_per_second"], "video_psnr_db": p["psnr_db"],
                               "reaches_stream": bool(good), "bitstream": bitstream,
                               "encode_ms": 1000.0 * p["encode_seconds"] / video["frames"]})
    return points


def decode_ms_and_sizes(a, point):
    """Decode milliseconds a frame (ffmpeg -benchmark's real time over the frames) and the frames'
    sizes in bytes, of one point's bitstream."""
    dec = run([a.ffmpeg, "-nostdin", "-hide_banner", "-benchmark", "-i", point["bitstream"], "-f", "null", "-"], "decode")
    sizes = [int(x) for x in run([a.ffprobe, "-v", "error", "-select_streams", "v", "-show_entries", "packet=size",
                                  "-of", "csv=p=0", point["bitstream"]], "ffprobe").split()]
    line = [l for l in dec.splitlines() if "rtime=" in l][-1]
    return 1000.0 * float(line.split("rtime=")[1].split("s")[0]) / len(sizes), sizes


def render_ms(a, work):
    """Median milliseconds to draw the stereo pair at the headset's size on this machine, as the
    viewers draw it by default (a pass per view, 4× MSAA, probe visibility)."""
    out = os.path.join(work, "raster.json")
    w, h = a.size.split("x")
    run([a.probecast, "bench", "raster", "--scene", a.scene, "--views", "stereo", "--size", w, h, "--msaa", "4",
         "--updates", "2", "--spp", "32", "--reference-spp", "2", "--repeats", str(a.repeats), "--json", out], "bench raster")
    return float(json.load(open(out))["view_sets"][0]["per_view_pass"]["ms_per_view_set"])


def summarise(profile, link, render, point):
    enc_ms, dec_ms = point["encode_ms"], point["decode_ms"]
    up, down = link["pose_up_ms"], link["frame_down_ms"]
    video50 = percentile(up, 0.5) + render + enc_ms + percentile(down, 0.5) + dec_ms
    video99 = percentile(up, 0.99) + render + enc_ms + percentile(down, 0.99) + dec_ms
    return {"profile": profile, "stream": point["stream"], "codec": point["codec"], "crf": point["crf"],
            "probe_pose_to_photon_ms": render, "probe_bytes_per_second": point["stream_bytes_per_second"],
            "lighting_age_ms_p50": link["lighting_age_p50"], "lighting_age_ms_p99": link["lighting_age_p99"],
            "video_pose_to_photon_ms_p50": video50, "video_pose_to_photon_ms_p99": video99,
            "video_bytes_per_second": point["video_bytes_per_second"], "video_reaches_stream": point["reaches_stream"],
            "components_ms": {"pose_up_p50": percentile(up, 0.5), "render": render, "encode": enc_ms,
                              "frame_down_p50": percentile(down, 0.5), "frame_down_p99": percentile(down, 0.99),
                              "decode": dec_ms, "frames_late": link["frames_late"]}}


def svg_chart(rows, path):
    """Pose-to-photon (median) against bytes per second, a panel per profile."""
    profiles = list(dict.fromkeys(r["profile"] for r in rows))
    w, h, pad = 320, 240, 44
    parts = ['<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" font-family="sans-serif" font-size="10">'
             % (w * len(profiles), h + 20)]
    top = max(max(r["video_pose_to_photon_ms_p50"] for r in rows), 1.0) * 1.1
    right = max(max(r["video_bytes_per_second"] for r in rows), 1.0) * 1.1
    for i, prof in enumerate(profiles):
        x0 = i * w
        X = lambda b: x0 + pad + (w - pad - 10) * b / right  # noqa: E731
        Y = lambda ms: h - pad + 10 - (h - pad - 10) * ms / top  # noqa: E731
        parts.append('<text x="%d" y="12">%s</text>' % (x0 + pad, prof))
        parts.append('<line x1="%d" y1="%d" x2="%d" y2="%d" stroke="black"/>' % (X(0), Y(0), X(right), Y(0)))
        parts.append('<line x1="%d" y1="%d" x2="%d" y2="%d" stroke="black"/>' % (X(0), Y(0), X(0), Y(top)))
        parts.append('<text x="%d" y="%d">%.0f ms</text>' % (x0 + 2, Y(top) + 10, top))
        parts.append('<text x="%d" y="%d">%.0f kB/s</text>' % (X(right) - 50, Y(0) + 14, right / 1000))
        for r in [r for r in rows if r["profile"] == prof]:
            parts.append('<circle cx="%.1f" cy="%.1f" r="4" fill="#1565c0"><title>probes %s</title></circle>'
                         % (X(r["probe_bytes_per_second"]), Y(r["probe_pose_to_photon_ms"]), r["stream"]))
            parts.append('<rect x="%.1f" y="%.1f" width="7" height="7" fill="#c62828"><title>%s for %s</title></rect>'
                         % (X(r["video_bytes_per_second"]) - 3.5, Y(r["video_pose_to_photon_ms_p50"]) - 3.5, r["codec"], r["stream"]))
    parts.append('<text x="4" y="%d">circles: probe client (its frame); squares: video (pose up, render, encode, '
                 'frame down, decode); x: bytes per second, y: pose to photon, median</text></svg>' % (h + 16))
    open(path, "w").write("\n".join(parts))


def parse_args():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--probecast", required=True)
    p.add_argument("--wan-link", required=True)
    p.add_argument("--ffmpeg", default="ffmpeg")
    p.add_argument("--ffprobe", default="ffprobe")
    p.add_argument("--scene", default="builtin:cornell")
    p.add_argument("--size", default="640x640", help="per eye, WxH")
    p.add_argument("--head-trace", default="builtin:mmsys18-user1")
    p.add_argument("--frames", type=int, default=60)
    p.add_argument("--warmup", type=int, default=8)
    p.add_argument("--streams", default="zh3,l2")
    p.add_argument("--codecs", default="av1-444,x265-444")
    p.add_argument("--x265-crf", default="12,20,28,36,44")
    p.add_argument("--av1-crf", default="20,32,44,56")
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--profiles", default=",".join(k for k in PROFILES if not k.startswith("slow")))
    p.add_argument("--seconds", type=float, default=12.0, help="link traffic per profile")
    p.add_argument("--video-json", help="a bench video run with --keep-files to take the frames from (default: run one)")
    p.add_argument("--work")
    p.add_argument("--json")
    p.add_argument("--svg")
    p.add_argument("--test", action="store_true", help="small frames, one profile, short runs, with assertions")
    a = p.parse_args()
    if a.test:
        a.size, a.frames, a.warmup, a.repeats, a.seconds = "96x96", 12, 2, 2, 5.0
        a.profiles, a.streams, a.codecs, a.x265_crf, a.av1_crf = "slow-100ms-1mbit", "zh3", "x265-444", "20,36", "32"
    return a


def measure(a, work):
    video = video_frames(a, work)
    points = equal_quality_points(video)
    render = render_ms(a, work)
    log("the stereo pair at %s per eye draws in %.1f ms here" % (a.size, render))
    for point in points:
        point["decode_ms"], point["sizes"] = decode_ms_and_sizes(a, point)
        log("%s for %s: CRF %d, %.0f B/s, encode %.1f ms, decode %.1f ms a frame"
            % (point["codec"], point["stream"], point["crf"], point["video_bytes_per_second"], point["encode_ms"], point["decode_ms"]))
    rows = []
    for profile in a.profiles.split(","):
        links = mtp_link.measure(a, work, profile, [p["sizes"] for p in points], video["fps"])
        rows += [summarise(profile, link, render, p) for p, link in zip(points, links)]
    return {"command": " ".join(sys.argv), "video_command": video.get("command"), "size_per_eye": a.size, "head_trace": a.head_trace, "fps": video["fps"],
            "render_ms": render, "video_reference": video["psnr"], "rows": rows}


def check(result):
    failures = 0
    for r in result["rows"]:
        ok = r["probe_pose_to_photon_ms"] < r["video_pose_to_photon_ms_p50"] and r["components_ms"]["frame_down_p50"] > 0
        ok = ok and r["components_ms"]["pose_up_p50"] >= PROFILES[r["profile"]][0] * 0.9
        print("%s: %s %s probes %.1f ms, video %.1f ms" % ("ok" if ok else "FAILED", r["profile"], r["codec"],
              r["probe_pose_to_photon_ms"], r["video_pose_to_photon_ms_p50"]))
        failures += 0 if ok else 1
    if not failures:
        print("motion_to_photon: the probe client's pose-to-photon is its frame; video's adds the link both ways")
    return failures


def main():
    a = parse_args()
    if os.geteuid() != 0 or not mtp_link.has_ip():
        print("needs root and iproute2: skipped")
        return 77
    work = a.work or tempfile.mkdtemp(prefix="probecast-mtp-")
    os.makedirs(work, exist_ok=True)
    result = measure(a, work)
    text = json.dumps(result, indent=1)
    if a.json:
        open(a.json, "w").write(text + "\n")
    else:
        print(text)
    if a.svg:
        svg_chart(result["rows"], a.svg)
    for r in result["rows"]:
        print("%-24s %-4s %-9s probes %6.1f ms (lighting %5.0f ms old) %6.0f B/s | video %6.1f ms (p99 %6.1f) %8.0f B/s"
              % (r["profile"], r["stream"], r["codec"], r["probe_pose_to_photon_ms"], r["lighting_age_ms_p50"],
                 r["probe_bytes_per_second"], r["video_pose_to_photon_ms_p50"], r["video_pose_to_photon_ms_p99"],
                 r["video_bytes_per_second"]), file=sys.stderr)
    return 1 if a.test and check(result) else 0


if __name__ == "__main__":
    sys.exit(main())
