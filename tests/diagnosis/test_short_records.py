"""A record too short for a test's windows: the test says it could not run, and the diagnosis goes
on (a bridge record resampled to its band, 225 samples a window, stopped `diagnose` with an order
error from inside the time-change test)."""

import numpy as np
import pytest

import armaxmodal as am
from armaxmodal.diagnosis.effects import run_tests
from armaxmodal.diagnosis.model import ModelSpec, Signals, fit_model
from armaxmodal.estimate.fit import record_supports
from armaxmodal.exceptions import OrderError


@pytest.mark.parametrize("orders", [(4, 3, 2, 0), (6, 5, 4, -3), (10, 16, 10, -5)])
def test_record_supports_is_the_rule_fit_armax_refuses_by(orders):
    """Around the shortest record a fit accepts: the predicate and the fitter's refusal agree at
    every length (an off-by-one in the start-up or the lead fails)."""
    rng = np.random.default_rng(0)
    u, y = rng.standard_normal(400), rng.standard_normal((400, 2))
    for n in range(40, 400, 3):
        try:
            am.fit_armax((u[:n], y[:n]), *orders, fs=50.0, shared_poles=True, max_iter=1, warn=False)
            fitted = True
        except OrderError:
            fitted = False
        assert fitted == record_supports(n, orders, 1, 2, True), n


def test_windows_too_short_for_the_model_skip_the_time_test_and_say_so():
    ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 22.0, seed=3), 60.0, noise=0.05,
                                 seed=4)  # fmt: skip
    s = Signals(ride.base, ride.response, ride.fs, ride.sensors, ride.input_name)
    findings, table = run_tests(fit_model(ModelSpec((20, 27, 20, -6)), s))
    assert "cannot hold the model's orders" in table["time_varying_not_run"]
    assert "time_varying_p" not in table and "time_varying" not in {f.effect for f in findings}


def test_a_record_the_band_would_leave_too_short_is_analysed_at_its_own_rate():
    """9 s at 240 Hz (2,160 samples) of a ride whose band ends at 28 Hz: resampled to the band it
    would keep about 600, too few to hold half out, so it is analysed as recorded."""
    from armaxmodal.diagnosis import diagnose

    ride = am.simulate_recording(am.supine_human(), am.random_vibration(240.0, 9.0, band=(0.5, 28.0), seed=5),
                                 240.0, noise=0.05, seed=6)  # fmt: skip
    d = diagnose(ride, max_rounds=0)
    assert d.recording.fs == 240.0 and d.recording.n_samples == ride.n_samples
    with pytest.raises(am.DataError, match="holding out half"):
        diagnose(am.Recording(240.0, ride.base[:700], ride.response[:700], ride.sensors))  # short as recorded
