"""A channel whose clock drifts (issue 70): named ``clock_drift`` on its channel (an output, or the
input when every output drifts alike), its rate held by its interval, taken out by resampling so the
held-out error falls; told from a constant delay, a gain change and a change of the structure; the
resampling checked against tones evaluated at the drifted times, the statistic against a slow
least-squares reference."""

from dataclasses import replace

import numpy as np
import pytest

import armaxmodal as am
from armaxmodal.diagnosis import diagnose
from armaxmodal.diagnosis.clock_drift import drift_rate, remaining_drift
from armaxmodal.diagnosis.effects import run_tests
from armaxmodal.diagnosis.inject import inject
from armaxmodal.diagnosis.model import ModelSpec, Signals, fit_model, fractional_shift, moved, usable
from armaxmodal.exceptions import DataError

ORDERS = (10, 16, 10, -5)  # the supine fixture's orders chosen by BIC (README)


@pytest.fixture(scope="module")
def clean(fixtures_dir):
    return am.read_recording(fixtures_dir / "supine_random.csv")


def _tests_on(rec):
    """The round's findings and statistics on the baseline fitted to ``rec``."""
    fitted = fit_model(ModelSpec(ORDERS), Signals(rec.base, rec.response, rec.fs, rec.sensors, rec.input_name))
    return run_tests(fitted)


@pytest.mark.parametrize(("samples", "rate"), [(0.0, 2.8e-4), (1.5, -1e-3), (-0.7, 3e-5)])
def test_the_resampling_reads_band_limited_data_on_the_drifted_times(samples, rate):
    """Tones up to 0.4 x fs, evaluated exactly at ``t + samples + rate (t - c)``: the error (7e-5 of
    the tones' 8, from the mirror's kink at the ends) is far below what a centre half a sample off
    makes (2e-3 and 6e-3 at the two larger rates)."""
    rng = np.random.default_rng(0)
    freqs, phases = rng.uniform(0.01, 0.4, 12), rng.uniform(0, 2 * np.pi, 12)
    n = 3000
    t = np.arange(n, dtype=float)

    def tones(times):
        return sum(np.cos(2 * np.pi * f * times + p) for f, p in zip(freqs, phases, strict=True))

    out = moved(tones(t), samples, rate)
    truth = tones(t + samples + rate * (t - (n - 1) / 2))
    inner = slice(100, n - 100)  # the mirror's edges, outside every error
    assert np.max(np.abs(out - truth)[inner]) < 2e-5 * np.max(np.abs(truth))


def test_no_drift_is_the_fourier_shift():
    x = np.random.default_rng(1).standard_normal(500)
    assert np.array_equal(moved(x, 2.3, 0.0), fractional_shift(x, 2.3))


def test_the_drift_statistic_is_the_least_squares_fit_with_the_delay_as_nuisance():
    """The rate against an explicit regression of the residual on ``[dz/dt, (t - c) dz/dt]``:
    dropping the nuisance column or flipping the sign fails (where the ramp is centred does not
    matter once the constant delay is a nuisance regressor)."""
    rng = np.random.default_rng(2)
    n = 2000
    t = np.arange(n)
    z = np.sin(2 * np.pi * 0.05 * t) + 0.5 * np.sin(2 * np.pi * 0.13 * t + 1.0)
    slope = 2 * np.pi * (0.05 * np.cos(2 * np.pi * 0.05 * t) + 0.5 * 0.13 * np.cos(2 * np.pi * 0.13 * t + 1.0))
    centred = t - (n - 1) / 2
    eps = 0.1 * rng.standard_normal(n) - (0.3 + 2e-4 * centred) * slope  # a delay of 0.3 and 200 ppm
    mask = np.zeros(n, bool)
    mask[50:-50] = True
    rate, sd = drift_rate(eps, z, mask, 0.1)
    design = np.column_stack([slope, centred * slope])[mask]
    (_, coef), *_ = np.linalg.lstsq(design, eps[mask], rcond=None)
    assert rate == pytest.approx(-coef, rel=1e-3)
    assert abs(rate - 2e-4) < 3 * sd and sd < 2e-5


@pytest.mark.parametrize(("channel", "rate_ppm"), [("chest", 120.0), ("base", -60.0)])
def test_a_clock_drift_is_named_measured_and_taken_out(clean, channel, rate_ppm):
    """An output's clock, or the input's (every output then drifts alike, and one finding names the
    input), running slow by ``rate_ppm``: the rate inside its interval, the resampled channel's
    simulation error far below the drifted one's."""
    d = diagnose(inject(clean, "clock_drift", [channel], rate_ppm=rate_ppm), max_rounds=1)
    (effect,) = d.effects
    assert effect.finding.effect == "clock_drift" and effect.finding.channels == (channel,)
    p = effect.parameters
    assert p["rate_ci95_ppm"][0] <= rate_ppm <= p["rate_ci95_ppm"][1] and np.ptp(p["rate_ci95_ppm"]) < 5
    assert p["rate_first_ppm"] == pytest.approx(rate_ppm, rel=0.1)  # the first-order reading, before the refits
    assert p["delay_change_ms"] == pytest.approx(1e-3 * rate_ppm * clean.duration, rel=0.02)
    # the rate reported is the model's, taken out by resampling, and what its residual still holds
    ((name, taken_out),) = d.final.model.spec.drifts
    left, _ = remaining_drift(d.final.model, channel)
    assert name == channel and p["rate_ppm"] == pytest.approx(1e6 * (taken_out + left), rel=1e-9)
    assert p["sim_error_after"] < 0.5 * p["sim_error_before"]


def test_the_resampled_ends_count_in_no_error():
    """A drift of 1000 ppm moves the ends of a 6,000-sample record 3 samples, which the mirror
    fills: they leave every error, as a shift's edge does."""
    spec = ModelSpec(ORDERS)
    plain, drifting = usable(6000, spec), usable(6000, replace(spec, drifts=(("head", 1e-3),)))
    assert plain.sum() - drifting.sum() == 2 * 3 and not drifting[~plain].any()


@pytest.mark.parametrize(
    ("effect", "params"),
    [("input_delay", {"samples": 2.4}), ("gain_change", {"time_s": 70.0, "factor": 1.2})],
)
def test_a_constant_delay_or_a_gain_change_is_no_clock_drift(clean, effect, params):
    """A delay that does not grow leaves no ramp once the delay is a nuisance; a gain change scales
    ``z``, which is uncorrelated with its own derivative."""
    findings, table = _tests_on(inject(clean, effect, ["chest"], **params))
    assert min(table["drift_p"]) > 0.01
    assert effect in {f.effect for f in findings} and "clock_drift" not in {f.effect for f in findings}


def test_outputs_that_drift_unalike_are_the_structure_not_a_clock():
    """Springs 12 % stiffer half way move each sensor's phase by its own amount: the drift test fires
    on the sensors, unalike, and no clock is named."""
    from tests.diagnosis.test_diagnose import _two_regimes

    findings, table = _tests_on(_two_regimes(1.12))
    assert min(table["drift_p"]) < 0.01 and "clock_drift" not in {f.effect for f in findings}


def test_a_clock_drift_planted_wrongly_is_refused(clean):
    with pytest.raises(DataError, match="rate_ppm"):
        inject(clean, "clock_drift", ["head"], rate_ppm=5e4)
    with pytest.raises(DataError, match="needs rate_ppm"):
        inject(clean, "clock_drift", ["head"])
