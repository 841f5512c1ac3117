"""Per-probe records: bit-identical to the C++ codec, and clear errors for wrong arrays."""
import numpy as np
import pytest

import probecast

REPRS = probecast.REPRESENTATIONS


def test_record_sizes_match_the_format():
    assert [probecast.record_size(r) for r in REPRS] == [13, 13, 16, 28, 56]


@pytest.mark.parametrize("repr_", REPRS)
def test_encode_is_bit_identical_to_cpp(golden, repr_):
    records = probecast.encode(golden["input"], repr_)
    assert records.dtype == np.uint8
    assert records.shape == (len(golden["input"]), probecast.record_size(repr_))
    np.testing.assert_array_equal(records, golden[repr_ + ".rec"])


@pytest.mark.parametrize("repr_", REPRS)
def test_decode_is_bit_identical_to_cpp(golden, repr_):
    probes = probecast.decode(golden[repr_ + ".rec"], repr_)
    assert probes.dtype == np.float32 and probes.shape == golden[repr_ + ".dec"].shape
    assert probes.tobytes() == golden[repr_ + ".dec"].tobytes()


@pytest.mark.parametrize("repr_", REPRS)
def test_round_trip_is_close_and_deterministic(rng, repr_):
    from conftest import random_probes

    p = random_probes(rng, 1000)
    rec = probecast.encode(p, repr_)
    q = probecast.decode(rec, repr_)
    assert np.array_equal(probecast.decode(rec, repr_), q)
    # RGB9E5 shares one exponent with 9 mantissa bits: error below 1/256 of the largest channel.
    dc_err = np.abs(q[:, :3] - p[:, :3]) / p[:, :3].max(axis=1, keepdims=True)
    assert dc_err.max() < 1.0 / 256


def test_zh3h_chooses_per_probe_and_the_per_pixel_band_adds_up(rng):
    from conftest import random_probes

    rec = probecast.encode(random_probes(rng, 50), "zh3h")
    per_pixel = probecast.decode(rec, "zh3h", zh3_per_pixel=True)
    per_probe = probecast.decode(rec, "zh3h")
    np.testing.assert_array_equal(per_pixel[:, :12], per_probe[:, :12])
    hallucinated = np.any(per_probe[:, 12:] != 0, axis=1)
    assert hallucinated.any()
    # The choice is the parity of the nine L1 ratio bytes: odd keeps plain L1.
    odd = rec[:, 4:13].astype(np.int64).sum(axis=1) % 2 == 1
    np.testing.assert_array_equal(odd, ~hallucinated)
    # Per pixel, a probe that hallucinates leaves the band to the renderer (0); one kept at plain L1
    # carries minus its hallucination, so that the renderer's cancels at the probe.
    assert np.all(per_pixel[hallucinated, 12:] == 0)
    assert np.all(np.any(per_pixel[~hallucinated, 12:] != 0, axis=1))


def test_empty_batch():
    assert probecast.encode(np.zeros((0, 27), np.float32), "l2").shape == (0, 28)
    assert probecast.decode(np.zeros((0, 28), np.uint8), "l2").shape == (0, 27)


@pytest.mark.parametrize(
    "bad, message",
    [
        (np.zeros((4, 27), np.float64), "dtype"),
        (np.zeros((4, 26), np.float32), "dimension 1 must be 27"),
        (np.zeros((27,), np.float32), "2 dimensions"),
        (np.zeros((4, 54), np.float32)[:, ::2], "C-contiguous"),
        ([[0.0] * 27], "incompatible function arguments"),  # not an array: TypeError
    ],
)
def test_encode_refuses_wrong_arrays(bad, message):
    with pytest.raises((ValueError, TypeError), match=message):
        probecast.encode(bad, "l1")


def test_decode_refuses_wrong_record_width_and_dtype():
    with pytest.raises(ValueError, match="dimension 1 must be 13"):
        probecast.decode(np.zeros((2, 16), np.uint8), "l1")
    with pytest.raises(ValueError, match="dtype"):
        probecast.decode(np.zeros((2, 13), np.int8), "l1")


def test_unknown_representation():
    with pytest.raises(ValueError, match="unknown representation 'l3'"):
        probecast.encode(np.zeros((1, 27), np.float32), "l3")


def test_fp16_record_with_nan_is_an_error():
    rec = np.zeros((1, 56), np.uint8)
    rec[0, 0:2] = [0x00, 0x7E]  # half NaN
    with pytest.raises(ValueError, match="Inf or NaN"):
        probecast.decode(rec, "fp16")


@pytest.mark.parametrize("repr_", REPRS)
def test_out_arrays_are_written_in_place_with_the_same_bytes(golden, repr_):
    records = np.full((len(golden["input"]), probecast.record_size(repr_)), 0xAB, dtype=np.uint8)
    returned = probecast.encode(golden["input"], repr_, out=records)
    assert returned is not None and np.shares_memory(returned, records)
    np.testing.assert_array_equal(records, golden[repr_ + ".rec"])
    probes = np.full(golden[repr_ + ".dec"].shape, np.nan, dtype=np.float32)
    probecast.decode(records, repr_, out=probes)
    assert probes.tobytes() == golden[repr_ + ".dec"].tobytes()


def test_out_arrays_of_the_wrong_kind_are_refused():
    p = np.zeros((4, 27), np.float32)
    with pytest.raises(ValueError, match="out: dimension 0 must be 4"):
        probecast.encode(p, "l1", out=np.zeros((3, 13), np.uint8))
    with pytest.raises(ValueError, match="out: expected dtype"):
        probecast.encode(p, "l1", out=np.zeros((4, 13), np.int16))
    with pytest.raises(ValueError, match="out: array is read-only"):
        ro = np.zeros((4, 27), np.float32)
        ro.flags.writeable = False
        probecast.decode(np.zeros((4, 13), np.uint8), "l1", out=ro)
    with pytest.raises(ValueError, match="C-contiguous"):
        probecast.decode(np.zeros((4, 13), np.uint8), "l1", out=np.zeros((27, 4), np.float32).T)
