"""Fixtures of the probecast Python tests: run by ctest as python.pytest (PYTHONPATH=build/python),
and by `scripts/dev.sh python` against the module installed by `pip install ./python`."""
import os
import subprocess

import numpy as np
import pytest

import probecast  # noqa: F401  (a missing module fails the run at collection, not skipped)

# Where the module must come from (scripts/dev.sh python: the virtual environment's site-packages),
# so that a module left in a build tree cannot pass for the installed one.
_expected_dir = os.environ.get("PROBECAST_EXPECT_MODULE_DIR", "")
if _expected_dir and os.path.dirname(os.path.realpath(probecast.__file__)) != os.path.realpath(_expected_dir):
    raise ImportError(f"probecast imported from {probecast.__file__}, not from {_expected_dir}")


def _golden_tool():
    return os.environ.get("PROBECAST_GOLDEN", "")


@pytest.fixture(scope="session")
def golden(tmp_path_factory):
    """What the C++ codec writes for a fixed input (python/golden_writer.cpp), as numpy arrays."""
    tool = _golden_tool()
    if not tool or not os.path.exists(tool):
        pytest.skip("PROBECAST_GOLDEN (the C++ golden writer) not set: run through ctest")
    out = tmp_path_factory.mktemp("golden")
    subprocess.run([tool, str(out)], check=True)

    def f32(name):
        return np.fromfile(out / name, dtype=np.float32).reshape(-1, 27)

    data = {"input": f32("input.f32"), "stream_input": [f32("stream_input0.f32"), f32("stream_input1.f32")]}
    for repr_ in probecast.REPRESENTATIONS:
        size = probecast.record_size(repr_)
        data[repr_ + ".rec"] = np.fromfile(out / (repr_ + ".rec"), dtype=np.uint8).reshape(-1, size)
        data[repr_ + ".dec"] = f32(repr_ + ".dec")
        raw = (out / ("stream_" + repr_ + ".bin")).read_bytes()
        frames, at = [], 0
        while at < len(raw):
            n = int.from_bytes(raw[at:at + 4], "little")
            frames.append(raw[at + 4:at + 4 + n])
            at += 4 + n
        data["stream_" + repr_] = frames
    return data


@pytest.fixture
def rng():
    return np.random.default_rng(7)


def random_probes(rng, n):
    """Plausible probes: positive DC, other coefficients within the ratio bounds of the DC."""
    p = np.empty((n, 27), np.float32)
    dc = rng.uniform(0.05, 20.0, size=(n, 3)).astype(np.float32)
    p[:, :3] = dc
    p[:, 3:] = (rng.uniform(-0.5, 0.5, size=(n, 24)) * np.tile(dc, 8)).astype(np.float32)
    return p
