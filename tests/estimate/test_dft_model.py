"""The modal model on DFT lines as an estimator: what it takes and what it returns, apart from the
selection that decides with it (tests/modes holds the count's and the refit's tests)."""

from __future__ import annotations

import numpy as np
import pytest

import armaxmodal as am
from armaxmodal._separable import SeparableModel, start_vector
from armaxmodal.estimate.dft_model import DftLines, fit_modal_model
from armaxmodal.modes.settings import DEFAULTS


@pytest.fixture(scope="module")
def ride():
    body = am.supine_human()
    rec = am.simulate_recording(body, am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03, seed=2)
    return body.modes(), DftLines.from_recording(rec, (0.5, 28.0))


def test_the_start_weights_leave_each_sensor_a_unit_residual_whatever_the_earlier_weights(ride):
    exact, data = ride
    f, x = exact.freq_hz * 1.02, exact.damping
    plain = data.weighted_at_start(f, x, DEFAULTS.dft)
    earlier = data.weighted(np.array([1.0, 3.0, 0.2, 7.0])).weighted_at_start(f, x, DEFAULTS.dft)
    np.testing.assert_allclose(earlier.weights, plain.weights, rtol=1e-9)
    np.testing.assert_allclose(earlier.y, plain.y, rtol=1e-9)
    held = SeparableModel(plain.s, plain.z_inv, plain.u, plain.y, plain.dt, "zoh")
    np.testing.assert_allclose(held.residual_rms(start_vector(f, x)), 1.0, rtol=1e-9)  # one over the noise level
    assert np.ptp(plain.weights) > 0.1 * plain.weights.max()  # the sensors' levels differ: a real weighting


def test_the_modes_come_in_the_start_order_when_asked_and_by_frequency_otherwise(ride):
    exact, data = ride
    f, x = exact.freq_hz[::-1], exact.damping[::-1]  # the start from the highest mode down
    as_started = fit_modal_model(data, f, x, "zoh", settings=DEFAULTS.dft, by_frequency=False)
    sorted_ = fit_modal_model(data, f, x, "zoh", settings=DEFAULTS.dft)
    assert np.all(np.diff(as_started.freq_hz) < 0) and np.all(np.diff(sorted_.freq_hz) > 0)
    np.testing.assert_allclose(as_started.freq_hz[::-1], sorted_.freq_hz, rtol=1e-12)
    np.testing.assert_allclose(as_started.shapes[:, ::-1], sorted_.shapes, rtol=1e-10)
    np.testing.assert_allclose(sorted_.freq_hz, exact.freq_hz, rtol=0.02)  # exact: 5.83, 8.31, 13.50, 16.25 Hz


def test_an_unknown_inter_sample_form_is_refused_before_a_fit(ride):
    exact, data = ride
    with pytest.raises(ValueError, match="hold: expected 'bandlimited' or 'zoh', got 'foh'"):
        fit_modal_model(data, exact.freq_hz, exact.damping, "foh", settings=DEFAULTS.dft)


def test_the_response_power_near_a_frequency_is_the_sum_of_its_lines():
    """Two sensors on the DFT grid (60 s at 60 Hz): sines of amplitude 2 at 5 Hz and 1 at 5.2 Hz on one,
    1 at 5 Hz on the other. A line holds ``(N A / 2)^2``, in the data's units whatever the weights;
    the reach is relative, 5 % of 5 Hz taking both lines, 2 % only the first."""
    t = np.arange(3600) / 60.0
    y = np.column_stack([2.0 * np.sin(2 * np.pi * 5.0 * t) + np.sin(2 * np.pi * 5.2 * t), np.sin(2 * np.pi * 5.0 * t)])
    rec = am.Recording(60.0, np.sin(2 * np.pi * 3.0 * t), y, ("head", "chest"))
    data = DftLines.from_recording(rec, (0.5, 28.0)).weighted(np.array([3.0, 0.5]))
    at_5, at_5_2 = (1800 * 2.0) ** 2 + 1800.0**2, 1800.0**2
    assert data.response_power(5.0, 0.05) == pytest.approx(at_5 + at_5_2, rel=1e-9)
    assert data.response_power(5.0, 0.02) == pytest.approx(at_5, rel=1e-9)
    assert data.response_power(10.0, 0.05) < 1e-12 * at_5
