"""The temporal stream: byte-identical frames to the C++ encoder, decoder equal to the encoder's
reconstruction bit for bit, and malformed bytes raising CodecError instead of crashing."""
import numpy as np
import pytest

import probecast
from conftest import random_probes

GRID = (6, 5, 3)


@pytest.mark.parametrize("repr_", probecast.REPRESENTATIONS)
def test_frames_are_byte_identical_to_cpp(golden, repr_):
    enc = probecast.StreamEncoder(GRID, repr_, brick=4, compress=False)
    enc.update(golden["stream_input"][0])
    key = enc.keyframe_frame()
    enc.update(golden["stream_input"][1])
    changed = enc.changed_frame()
    assert isinstance(key, bytes)
    assert [key, changed] == golden["stream_" + repr_]


@pytest.mark.parametrize("repr_", probecast.REPRESENTATIONS)
@pytest.mark.parametrize("deadzone", [0, 2])
def test_decoder_matches_encoder_reconstruction(rng, repr_, deadzone):
    grid = (9, 4, 7)
    n = grid[0] * grid[1] * grid[2]
    enc = probecast.StreamEncoder(grid, repr_, brick=4, deadzone=deadzone)
    dec = probecast.StreamDecoder(grid, repr_, brick=4)
    assert enc.count == n and dec.count == n
    base = random_probes(rng, n)
    active = (rng.uniform(size=n) > 0.2).astype(np.uint8)
    for f in range(5):
        frame_probes = (base * (1.0 + 0.05 * f)).astype(np.float32)
        changed = enc.update(frame_probes, active if f >= 2 else None)
        assert changed >= 0
        dec.apply(enc.changed_frame())
        assert dec.probes().tobytes() == enc.reconstruction().tobytes()
        np.testing.assert_array_equal(dec.active(), enc.active())
    # A new subscriber joining with a keyframe frame reaches the same state.
    late = probecast.StreamDecoder(grid, repr_, brick=4)
    late.apply(enc.keyframe_frame())
    assert late.probes().tobytes() == enc.reconstruction().tobytes()
    assert np.all(late.probes()[active == 0] == 0)


def test_active_accepts_bool_and_refuses_wrong_length(rng):
    enc = probecast.StreamEncoder((4, 4, 4), "l1")
    p = random_probes(rng, 64)
    enc.update(p, np.ones(64, bool))
    with pytest.raises(ValueError, match="active"):
        enc.update(p, np.ones(63, np.uint8))
    with pytest.raises(ValueError, match="dimension 0 must be 64"):
        enc.update(p[:10])


def test_bad_stream_arguments():
    with pytest.raises(ValueError, match="brick"):
        probecast.StreamEncoder((4, 4, 4), "l1", brick=9)
    with pytest.raises(ValueError, match="grid"):
        probecast.StreamDecoder((0, 4, 4), "l1")
    with pytest.raises(ValueError, match="unknown representation"):
        probecast.StreamDecoder((4, 4, 4), "sh4")


def _frame(rng, repr_="zh3"):
    enc = probecast.StreamEncoder((5, 4, 3), repr_)
    enc.update(random_probes(rng, 60))
    return enc.keyframe_frame()


def test_malformed_frames_raise_codec_error_with_status(rng):
    frame = _frame(rng)
    dec = probecast.StreamDecoder((5, 4, 3), "zh3")
    cases = {
        b"": "Truncated",
        frame[:20]: "Truncated",
        b"XXXX" + frame[4:]: "BadMagic",
        frame + b"\0": "TrailingBytes",
    }
    flipped = bytearray(frame)
    flipped[10] ^= 0x40  # inside the header: its CRC no longer matches
    cases[bytes(flipped)] = "HeaderChecksum"
    for data, status in cases.items():
        with pytest.raises(probecast.CodecError, match=status) as info:
            dec.apply(data)
        assert info.value.status == getattr(probecast.CodecStatus, status)
        assert info.value.status.name == status
        assert isinstance(info.value, ValueError)
    assert np.all(dec.probes() == 0)  # all or nothing: nothing was applied
    with pytest.raises(probecast.CodecError) as info:
        probecast.StreamDecoder((5, 4, 4), "zh3").apply(frame)
    assert info.value.status == probecast.CodecStatus.LayoutMismatch
    dec.apply(frame)  # the intact frame still decodes


def test_every_truncation_and_byte_flip_is_an_error_not_a_crash(rng):
    frame = _frame(rng, "l2")
    dec = probecast.StreamDecoder((5, 4, 3), "l2")
    statuses = set()
    for cut in range(len(frame)):
        with pytest.raises(probecast.CodecError) as info:
            dec.apply(frame[:cut])
        statuses.add(info.value.status.name)
    for at in range(0, len(frame), max(1, len(frame) // 200)):
        data = bytearray(frame)
        data[at] ^= 0xFF
        with pytest.raises(probecast.CodecError):
            dec.apply(bytes(data))
    assert "Truncated" in statuses
    assert np.all(dec.probes() == 0)


def test_error_bound_mixes_brick_representations_in_one_stream(rng):
    # Two bricks along x: a uniform sky over one (L1 is exact there), three lights per probe over
    # the other. With a bound the sky's brick goes as l1 in the l2 stream: a smaller keyframe,
    # decoded bit for bit as the encoder reconstructs it.
    grid = (8, 4, 4)
    n = 128
    probes = random_probes(rng, n)
    sky = np.zeros(27, np.float32)
    sky[:3] = 3.5449077 * np.array([0.5, 0.6, 0.7], np.float32)
    x = np.arange(n) % 8
    probes[x < 4] = sky
    plain = probecast.StreamEncoder(grid, "l2", compress=False)
    bounded = probecast.StreamEncoder(grid, "l2", compress=False, error_bound=0.05)
    plain.update(probes)
    bounded.update(probes)
    key = bounded.keyframe_frame()
    assert len(key) < len(plain.keyframe_frame()) - 64 * (28 - 13) + 64
    dec = probecast.StreamDecoder(grid, "l2")
    dec.apply(key)
    assert dec.probes().tobytes() == bounded.reconstruction().tobytes()
    np.testing.assert_array_equal(dec.probes()[x < 4, 12:], 0)  # the sky's brick holds no L2 band
    with pytest.raises(ValueError, match="has none"):
        probecast.StreamEncoder(grid, "l1", error_bound=0.05)
    with pytest.raises(ValueError, match="error_bound"):
        probecast.StreamEncoder(grid, "l2", error_bound=-1.0)
