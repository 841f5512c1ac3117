#!/usr/bin/env python3
"""Irradiance error against bytes per probe for every representation and dead-zone.

    PYTHONPATH=build/python /usr/bin/python3 examples/codec_size_quality.py [--envmaps DIR | --probes FILE] [--out DIR]

Records: each map's float L2 SH (or each active probe of a baked volume) through one record of
each representation; error = irradiance relative RMSE (RGB pooled) against the brute-force
irradiance of the map at equal-area normals, as `probecast bench codec` measures it (for a volume:
exact over the sphere against its own float L2).
Streams: a grid of probes whose light turns about +Y (maps) or gets 1 % noise per frame (volume),
through the temporal coder at each dead-zone; bytes = changed frames (headers included) per probe
per frame, error = exact irradiance RMSE against the noise-free input.
Writes size_quality.svg, size_quality.png and size_quality.json into --out.
"""
import argparse
import json
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import probecast  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]


def record_errors_maps(maps, normals_count):
    normals = probecast.fibonacci_sphere(normals_count)
    errors = {r: [] for r in probecast.REPRESENTATIONS}
    for img in maps:
        probe = probecast.project_equirect(img)
        factor = max(1, img.shape[1] // 256)
        ref = probecast.brute_force_irradiance(probecast.downsample(img, factor) if factor > 1 else img, normals)
        for r in probecast.REPRESENTATIONS:
            q = probecast.decode(probecast.encode(probe[None], r), r)[0]
            errors[r].append(probecast.irradiance_rmse_rel(q, normals, ref))
    return {r: float(np.mean(e)) for r, e in errors.items()}


def record_errors_volume(probes):
    return {r: probecast.irradiance_rmse_rel_sh(probecast.decode(probecast.encode(probes, r), r), probes)
            for r in probecast.REPRESENTATIONS}


def frames_from_maps(maps, grid, frames):
    """Clean frames of a grid lit by the first map turning 0.5 degree per frame, 4 phases, per-probe gain."""
    small = probecast.downsample(maps[0], max(1, maps[0].shape[1] // 128))
    n = grid[0] * grid[1] * grid[2]
    gain = (0.3 + 1.7 * ((np.arange(n, dtype=np.uint64) * 2654435761) % 1000) / 1000.0).astype(np.float32)
    phase = np.arange(n) % 4
    out = []
    for f in range(frames):
        by_phase = np.stack([probecast.project_equirect(small, np.radians(0.5 * f + 15.0 * k)) for k in range(4)])
        out.append(np.ascontiguousarray(by_phase[phase] * gain[:, None], dtype=np.float32))
    return out, None


def frames_from_volume(volume, frames, rng):
    p = volume["probes"]
    return [p] * frames, volume["active"]


def stream_errors(clean, active, grid, deadzones, rng, noise=0.01):
    results = {}
    noisy = [np.ascontiguousarray(c + noise * np.tile(c[:, :3], 9) * rng.standard_normal(c.shape).astype(np.float32),
                                  dtype=np.float32) for c in clean]
    n = clean[0].shape[0]
    for r in probecast.REPRESENTATIONS:
        points = []
        for dz in deadzones:
            if r == "fp16" and dz > 0:
                continue  # fp16 steps are not ratio steps
            enc = probecast.StreamEncoder(grid, r, brick=4, deadzone=dz)
            dec = probecast.StreamDecoder(grid, r, brick=4)
            sent, err_num, err_den = 0, [], []
            for f, frame in enumerate(noisy):
                enc.update(frame, active)
                data = enc.changed_frame()
                dec.apply(data)
                if f == 0:
                    continue
                sent += len(data)
                held = dec.probes()
                mask = slice(None) if active is None else active.astype(bool)
                err_num.append(held[mask])
                err_den.append(clean[f][mask])
            rmse = probecast.irradiance_rmse_rel_sh(np.ascontiguousarray(np.concatenate(err_num)),
                                                    np.ascontiguousarray(np.concatenate(err_den)))
            points.append({"deadzone": dz, "bytes_per_probe_per_frame": sent / ((len(noisy) - 1) * n),
                           "irradiance_rmse_rel": rmse})
        results[r] = points
    return results


def plot(records, streams, title, out):
    fig, ax = plt.subplots(figsize=(8, 5.5), dpi=110)
    xs = [probecast.record_size(r) for r in records]
    ax.plot(xs, list(records.values()), "ko", label="records (one per probe)")
    for r, x in zip(records, xs):
        ax.annotate(r, (x, records[r]), textcoords="offset points", xytext=(5, 5), fontsize=9)
    for r, pts in streams.items():
        x = [p["bytes_per_probe_per_frame"] for p in pts]
        y = [p["irradiance_rmse_rel"] for p in pts]
        (line,) = ax.plot(x, y, "-s", ms=4, label=f"{r} stream")
        for p in pts:
            ax.annotate(f"dz{p['deadzone']}", (p["bytes_per_probe_per_frame"], p["irradiance_rmse_rel"]),
                        textcoords="offset points", xytext=(3, -10), fontsize=7, color=line.get_color())
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("bytes per probe (records) / per probe per frame (streams)")
    ax.set_ylabel("irradiance relative RMSE")
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    out.mkdir(parents=True, exist_ok=True)
    fig.savefig(out / "size_quality.svg")
    fig.savefig(out / "size_quality.png")
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description="irradiance error against bytes per probe (representations, dead-zones)")
    src = ap.add_mutually_exclusive_group()
    src.add_argument("--envmaps", default=str(ROOT / "tests" / "data" / "envmaps"), help="folder of equirect .hdr/.exr")
    src.add_argument("--probes", help="a baked probe volume file (probecast bake) instead of env maps")
    ap.add_argument("--out", default=str(ROOT / "out" / "codec_size_quality"))
    ap.add_argument("--deadzones", type=int, nargs="+", default=[0, 1, 2, 4, 8])
    ap.add_argument("--frames", type=int, default=30)
    ap.add_argument("--normals", type=int, default=2048)
    args = ap.parse_args()
    rng = np.random.default_rng(2)
    out = pathlib.Path(args.out)

    if args.probes:
        volume = probecast.read_probe_file(args.probes)
        active = volume["active"].astype(bool)
        records = record_errors_volume(np.ascontiguousarray(volume["probes"][active]))
        grid = volume["dims"]
        clean, mask = frames_from_volume(volume, args.frames, rng)
        title = f"{pathlib.Path(args.probes).name}: {int(active.sum())} active probes (error vs its float L2)"
    else:
        paths = sorted(pathlib.Path(args.envmaps).glob("*.hdr")) + sorted(pathlib.Path(args.envmaps).glob("*.exr"))
        if not paths:
            ap.error(f"no .hdr or .exr maps in {args.envmaps}")
        maps = [probecast.load_envmap(str(p)) for p in paths]
        records = record_errors_maps(maps, args.normals)
        grid = (16, 4, 16)
        clean, mask = frames_from_maps(maps, grid, args.frames)
        title = f"{len(paths)} env maps ({', '.join(p.stem for p in paths)}); streams: 16x4x16 grid, 1% noise"
    streams = stream_errors(clean, mask, grid, args.deadzones, rng)
    title += "\nrecords: error vs " + ("float L2" if args.probes else "brute-force irradiance") + "; streams: vs noise-free float L2"
    plot(records, streams, "probecast: irradiance error against bytes per probe\n" + title, out)
    (out / "size_quality.json").write_text(json.dumps({"records": records, "streams": streams}, indent=2))
    for r, e in records.items():
        print(f"{r:<5} {probecast.record_size(r):>3} B/probe  record error {100 * e:6.2f}%  stream "
              + "  ".join(f"dz{p['deadzone']} {p['bytes_per_probe_per_frame']:.2f} B {100 * p['irradiance_rmse_rel']:.2f}%"
                          for p in streams[r]))
    print(f"wrote {out / 'size_quality.svg'} and {out / 'size_quality.png'}")


if __name__ == "__main__":
    main()
