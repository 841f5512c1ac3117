"""Probe volume files written and read back through the C++ reader and writer."""
import numpy as np
import pytest

import probecast
from conftest import random_probes


def test_probe_file_round_trip(tmp_path, rng):
    dims = (3, 4, 5)
    p = random_probes(rng, 60)
    active = (np.arange(60) % 7 != 0).astype(np.uint8)
    path = str(tmp_path / "v.pcpv")
    probecast.write_probe_file(path, dims, p, active, bounds_min=(-2, 0, -1.5), bounds_max=(2, 3, 1.5), updates=12,
                               samples_per_probe=256)
    v = probecast.read_probe_file(path)
    assert v["dims"] == dims
    assert v["bounds_min"] == (-2.0, 0.0, -1.5) and v["bounds_max"] == (2.0, 3.0, 1.5)
    assert v["updates"] == 12 and v["samples_per_probe"] == 256
    assert v["probes"].dtype == np.float32 and v["probes"].tobytes() == p.tobytes()
    np.testing.assert_array_equal(v["active"], active)


def test_probe_file_defaults_to_all_active(tmp_path, rng):
    path = str(tmp_path / "v.pcpv")
    probecast.write_probe_file(path, (2, 2, 2), random_probes(rng, 8))
    assert np.all(probecast.read_probe_file(path)["active"] == 1)


def test_probe_file_errors(tmp_path, rng):
    bad = tmp_path / "bad.pcpv"
    bad.write_bytes(b"PCPV" + b"\0" * 40)
    with pytest.raises(ValueError):
        probecast.read_probe_file(str(bad))
    with pytest.raises(ValueError):
        probecast.read_probe_file(str(tmp_path / "missing.pcpv"))
    p = random_probes(rng, 8)
    p[3, 5] = np.nan
    with pytest.raises(ValueError):
        probecast.write_probe_file(str(tmp_path / "nan.pcpv"), (2, 2, 2), p)
    with pytest.raises(ValueError, match="dimension 0 must be 8"):
        probecast.write_probe_file(str(tmp_path / "x.pcpv"), (2, 2, 2), random_probes(rng, 7))


def _crc32c(data):
    crc = 0xFFFFFFFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = (crc >> 1) ^ (0x82F63B78 if crc & 1 else 0)
    return crc ^ 0xFFFFFFFF


def test_probe_file_names_its_scene(tmp_path, rng):
    import hashlib
    import struct
    path = tmp_path / "v.pcpv"
    probecast.write_probe_file(str(path), (2, 1, 1), random_probes(rng, 2))
    v = probecast.read_probe_file(str(path))
    assert v["scene_hash"] is None and v["scene_manifest"] is None and v["scene_time"] == 0.0
    # The same file naming a scene at scene time 0.75 (version 4's tail: hash, time, manifest, CRC).
    manifest = b'{"files":[],"format":1,"lighting":{},"scene":{"builtin":"cornell"}}'
    digest = hashlib.sha256(manifest).digest()
    body = path.read_bytes()[:-48] + digest + struct.pack("<dI", 0.75, len(manifest)) + manifest
    path.write_bytes(body + struct.pack("<I", _crc32c(body)))
    v = probecast.read_probe_file(str(path))
    assert v["scene_hash"] == digest.hex() and v["scene_manifest"] == manifest.decode() and v["scene_time"] == 0.75
