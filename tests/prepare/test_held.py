"""``held_samples``: a channel sampled at a lower rate and forward-filled to the record's."""

import numpy as np
import pytest

import armaxmodal as am
from armaxmodal.prepare.checks import check_quality
from armaxmodal.prepare.held import held_channels
from armaxmodal.prepare.preparation import prepare


@pytest.fixture(scope="module")
def clean(fixtures_dir):
    return am.read_recording(fixtures_dir / "supine_random.csv")


def _held(x: np.ndarray, fs: float, own_rate: float) -> np.ndarray:
    """``x`` sampled at ``own_rate`` and held: each sample repeats the last one at or
    before its time on the slower clock."""
    t = np.arange(x.size) / fs
    return x[np.floor(np.floor(t * own_rate + 1e-9) / own_rate * fs + 1e-9).astype(int)]


def _interpolated(x: np.ndarray, fs: float, own_rate: float) -> np.ndarray:
    """``x`` sampled at ``own_rate`` and joined by straight lines at the record's rate."""
    t = np.arange(x.size) / fs
    slow = np.arange(0.0, t[-1] + 1e-9, 1.0 / own_rate)
    return np.interp(t, slow, x[np.rint(slow * fs).astype(int)])


def _with(rec, column: int, values) -> am.Recording:
    y = rec.response.copy()
    y[:, column] = values
    return am.Recording(rec.fs, rec.base, y, rec.sensors)


@pytest.mark.parametrize("own_rate, cycle", [(30.0, 2), (15.0, 4), (50.0, 6), (20.0, 3)])
def test_a_held_channel_is_found_with_its_own_rate(clean, own_rate, cycle):
    rec = _with(clean, 1, _held(clean.response[:, 1], clean.fs, own_rate))
    (found,) = held_channels(rec)
    assert found.name == "chest" and found.cycle == cycle
    assert found.own_rate_hz == pytest.approx(own_rate, rel=0.002)
    assert found.repeat_share == pytest.approx(1 - own_rate / clean.fs, abs=0.002)
    assert found.p < 1e-100


@pytest.mark.parametrize("digits", [None, 6])
@pytest.mark.parametrize("own_rate, cycle", [(30.0, 2), (20.0, 3)])
def test_an_interpolated_channel_is_found_with_its_own_rate(clean, own_rate, cycle, digits):
    """Straight lines between a slower channel's samples, also as a CSV with 6 significant
    digits keeps them (its rounding is far under the tolerance)."""
    x = _interpolated(clean.response[:, 1], clean.fs, own_rate)
    if digits is not None:
        x = np.array([float(f"{v:.{digits}g}") for v in x])
    (found,) = held_channels(_with(clean, 1, x))
    assert (found.name, found.how, found.cycle) == ("chest", "interpolated", cycle)
    assert found.own_rate_hz == pytest.approx(own_rate, rel=0.002) and found.p < 1e-100


def test_a_held_input_is_named_as_the_input(clean):
    rec = am.Recording(clean.fs, _held(clean.base, clean.fs, 30.0), clean.response, clean.sensors)
    (warning,) = [w for w in check_quality(rec) if w.code == "held_samples"]
    assert warning.channels == ("base",) and "the input 'base'" in warning.message
    assert "about 30 Hz" in warning.message and "--band LO:12" in warning.message


@pytest.mark.parametrize("step_in_sd", [0.3, 1.0])
def test_repeats_without_a_cycle_are_not_named(clean, step_in_sd):
    """A coarse quantiser repeats samples too (12 % and 4 % of the steps here), at no phase."""
    x = clean.response[:, 2]
    q = step_in_sd * x.std()
    rec = _with(clean, 2, np.round(x / q) * q)
    assert np.mean(np.diff(rec.response[:, 2]) == 0) > 0.03
    assert held_channels(rec) == []


def test_the_fixtures_have_no_held_channel(fixtures_dir):
    for path in sorted(fixtures_dir.glob("*.csv")):
        assert held_channels(am.read_recording(path)) == [], path.name


def test_a_held_output_is_left_out_unless_the_band_is_below_its_rate(clean):
    """Pooled, head held at half rate cost the supine ride two of its four modes; left out,
    the fit is the one of the other three sensors."""
    rec = _with(clean, 0, _held(clean.response[:, 0], clean.fs, 30.0))
    prep = prepare(rec)
    assert prep.recording.sensors == ("chest", "pelvis", "legs") and prep.dropped == ("head",)
    (warning,) = [w for w in prep.warnings if w.code == "held_samples"]
    assert warning.message.endswith("it was left out of the fit.")
    others = prepare(clean.select(["chest", "pelvis", "legs"])).recording
    np.testing.assert_array_equal(prep.recording.response, others.response)
    # analysed below 0.4 of its own rate, the resampling's filter removes its images: kept
    kept = prepare(rec, band=(0.5, 11.0))
    assert "head" in kept.recording.sensors and not kept.dropped
    # every output held alike: nothing to fit without them, so they stay, named
    every = np.column_stack([_held(c, clean.fs, 30.0) for c in clean.response.T])
    both = am.Recording(clean.fs, clean.base, every, clean.sensors)
    assert prepare(both).recording.sensors == clean.sensors


def test_a_rate_a_hair_below_the_records_is_not_named(clean):
    """59 Hz held to 60 Hz repeats one sample in 60 at one phase: its images are negligible,
    and leaving the channel out would cost more than it saves."""
    rec = _with(clean, 1, _held(clean.response[:, 1], clean.fs, 59.0))
    assert 0.01 < np.mean(np.diff(rec.response[:, 1]) == 0) < 0.1
    assert held_channels(rec) == []


def test_repeats_at_random_samples_are_not_named(clean):
    """A reader that repeats the last value when a read fails does it at random samples:
    20 % repeats at no phase, on five seeds, are named nowhere."""
    for seed in range(5):
        x = clean.response[:, 3].copy()
        rng = np.random.default_rng(seed)
        for i in np.sort(rng.choice(np.arange(1, x.size), x.size // 5, replace=False)):
            x[i] = x[i - 1]
        assert held_channels(_with(clean, 3, x)) == [], seed
