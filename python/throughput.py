#!/usr/bin/env python3
"""Encode and decode throughput of the Python module, to set against `probecast bench codec`.

    PYTHONPATH=build/python /usr/bin/python3 python/throughput.py [--probes 1000000] [--repeats 5]

Probes are the project's two maps' SH at random intensities (as the bench's throughput set); the
median of the repeats is printed in million probes per second, one thread (the GIL is released
inside each call, so threads could run batches in parallel).
"""
import argparse
import pathlib
import time

import numpy as np

import probecast


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--probes", type=int, default=1_000_000)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--envmaps", default=str(pathlib.Path(__file__).resolve().parents[1] / "tests" / "data" / "envmaps"))
    ap.add_argument("--repr", nargs="+", default=list(probecast.REPRESENTATIONS))
    args = ap.parse_args()

    maps = sorted(pathlib.Path(args.envmaps).glob("*.hdr")) + sorted(pathlib.Path(args.envmaps).glob("*.exr"))
    sources = np.stack([probecast.project_equirect(probecast.load_envmap(str(m))) for m in maps])
    rng = np.random.default_rng(1)
    scale = rng.uniform(0.05, 20.0, size=(args.probes, 1)).astype(np.float32)
    probes = np.ascontiguousarray(sources[np.arange(args.probes) % len(sources)] * scale, dtype=np.float32)

    print(f"{args.probes} probes, median of {args.repeats}, one thread")
    print(f"{'repr':<6} {'encode Mpr/s':>14} {'decode Mpr/s':>14}")
    decoded = np.empty_like(probes)
    for r in args.repr:
        enc, dec = [], []
        # Outputs allocated once and reused (out=), as the C++ bench reuses its buffers: the figure
        # is the codec's, not the first touch of 100 MB of new pages.
        records = np.empty((args.probes, probecast.record_size(r)), dtype=np.uint8)
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            probecast.encode(probes, r, out=records)
            t1 = time.perf_counter()
            probecast.decode(records, r, out=decoded)
            t2 = time.perf_counter()
            enc.append(args.probes / (t1 - t0))
            dec.append(args.probes / (t2 - t1))
        print(f"{r:<6} {np.median(enc) / 1e6:>14.2f} {np.median(dec) / 1e6:>14.2f}")


if __name__ == "__main__":
    main()
