"""Which world a record is in (issue 67): the local polynomial method's noise against a slow
reference and a known noise level, the adequacy test on a right, a short and a wrong model, and the
count that runs by the criterion and the halves where its model is adequate and by the stated rule
(a stable diagram column as well) where it is not."""

from types import SimpleNamespace

import numpy as np
import pytest

import armaxmodal as am
from armaxmodal.estimate.dft_model import DftLines, fit_modal_model
from armaxmodal.modes.count_search import count_modes
from armaxmodal.modes.counted import without_column
from armaxmodal.modes.mode_count import COLUMN_RULE, LIKELIHOOD_RULE, Adequacy, model_adequacy
from armaxmodal.modes.notes import rule_notes
from armaxmodal.modes.settings import DEFAULTS
from armaxmodal.spectra import local_polynomial_noise
from tests import naive

LEVEL = DEFAULTS.count.adequacy_ratio
#: the vectorised and the one-line-at-a-time least squares differ by rounding only
SAME = 1e-9
#: the mean of 4,000 lines' variance, each of 14 real degrees of freedom, is within 3 % of the truth
#: (its relative standard deviation is about 0.4 %; neighbouring windows share lines)
NOISE_TOL = 0.03
#: a right model's ratio on a 120 s ride: 1 within a few hundredths (0.98-1.01 on this ride)
RIGHT_TOL = 0.05


def test_lpm_matches_the_slow_reference():
    rng = np.random.default_rng(3)
    u = rng.standard_normal(200) + 1j * rng.standard_normal(200)
    y = rng.standard_normal((200, 2)) + 1j * rng.standard_normal((200, 2))
    fast = local_polynomial_noise(u, y, 6, 2)
    slow = naive.local_polynomial_noise(u, y, 6, 2)
    np.testing.assert_allclose(fast, slow, rtol=SAME)
    np.testing.assert_allclose(local_polynomial_noise(u, y, 4, 1), naive.local_polynomial_noise(u, y, 4, 1), rtol=SAME)


def test_lpm_measures_a_known_noise_that_varies_with_frequency():
    """An FRF and a leakage term smooth over a window, noise whose level doubles across the band: the
    method's variance follows the truth in each half, whatever the FRF and transient."""
    rng = np.random.default_rng(4)
    n = 8000
    w = np.linspace(0.0, 1.0, n)
    u = rng.standard_normal(n) + 1j * rng.standard_normal(n)
    level = np.where(w < 0.5, 0.05, 0.1)  # E|V|^2 = 2 level^2
    v = level * (rng.standard_normal(n) + 1j * rng.standard_normal(n))
    y = (3.0 / (1.0 + 2j * w)) * u + (0.5 - 0.3j) * np.exp(-2j * w) + v
    var = local_polynomial_noise(u, y[:, None])[:, 0]
    for half in (w < 0.5, w >= 0.5):
        truth = 2 * level[half][0] ** 2
        assert abs(var[half].mean() / truth - 1) < NOISE_TOL


def test_lpm_refuses_too_few_lines_and_arrays_of_other_shapes():
    with pytest.raises(ValueError, match="lines"):
        local_polynomial_noise(np.ones(5), np.ones((5, 1)))
    with pytest.raises(ValueError, match=r"got \(40,\) and \(39, 1\)"):  # not the input's lines
        local_polynomial_noise(np.ones(40), np.ones((39, 1)))
    with pytest.raises(ValueError, match="one output per column"):  # one output given as a vector
        local_polynomial_noise(np.ones(40), np.ones(40))


@pytest.fixture(scope="module")
def ride():
    u = am.random_vibration(60.0, 120.0, (0.5, 28.0), seed=21)
    return am.simulate_recording(am.supine_human(), u, 60.0, noise=0.03, seed=22)


def _ratio(rec, n_modes=4):
    exact = am.supine_human().modes()
    data = DftLines.from_recording(rec, (0.5, 27.0))
    model = fit_modal_model(data, exact.freq_hz[:n_modes], exact.damping[:n_modes], "zoh", 100, settings=DEFAULTS.dft)
    return model_adequacy(model, data.u, LEVEL)


def test_the_right_model_is_adequate(ride):
    test = _ratio(ride)
    assert test.adequate and test.rule == LIKELIHOOD_RULE
    np.testing.assert_allclose(test.ratio, 1.0, atol=RIGHT_TOL)


def test_a_model_one_mode_short_is_not(ride):
    """The 16.25 Hz mode left out: its response stays in the residual, above the noise on the sensors
    that see it (1.3-4 times)."""
    test = _ratio(ride, 3)
    assert not test.adequate and test.rule == COLUMN_RULE
    assert np.max(test.ratio) > 2 * LEVEL


def test_outputs_that_lead_the_input_are_not_explained(ride):
    """Outputs 3 samples ahead of the input (a bridge deck before its column base): no modal sum of a
    causal model follows the phase, and every sensor's ratio is far above the level."""
    led = am.Recording(ride.fs, ride.base, np.roll(ride.response, -3, axis=0), ride.sensors)
    assert np.all(_ratio(led).ratio > 10 * LEVEL)


def test_the_json_form_is_strict():
    out = Adequacy(np.array([0.99, np.nan]), LEVEL).to_dict()
    assert out == {"ratio": [0.99, None], "level": LEVEL, "adequate": False, "rule": COLUMN_RULE}


# -- the count in the two worlds -----------------------------------------------------------------


def _count(rec, n_start):
    exact = am.supine_human().modes()
    data = DftLines.from_recording(rec, (0.5, 27.0))
    halves = tuple(DftLines.from_recording(h, (0.5, 27.0)) for h in rec.split(2))
    return count_modes(data, exact.freq_hz[:n_start], exact.damping[:n_start], hold="zoh", halves=halves,
                       supported=lambda f, x: False, n_jobs=1)  # fmt: skip


def test_where_the_model_is_adequate_no_diagram_column_refuses_a_mode(ride):
    """Started one mode short on a diagram with no column: the criterion and the halves add it, as
    the record's adequate model asks (the gate used to refuse it)."""
    count = _count(ride, 3)
    assert count.adequacy.adequate and count.rule_refused == ()
    assert count.model.n_modes == 4 and [s.action for s in count.steps] == ["add"]
    assert abs(np.sort(count.model.freq_hz)[-1] / 16.25 - 1) < 0.02


def test_where_it_is_not_the_stated_rule_decides(ride):
    """Outputs leading the input: the model is not adequate, so the search runs again under the rule
    (both searches' fits in the table, each from its start); with no column anywhere no mode of the
    band is added (the poles it adds are lines at Nyquist, not modes), and the note names the rule."""
    led = am.Recording(ride.fs, ride.base, np.roll(ride.response, -3, axis=0), ride.sensors)
    count = _count(led, 4)
    assert not count.adequacy.adequate
    assert [m.action for m in count.models].count("start") == 2
    exact = am.supine_human().modes().freq_hz
    for f in count.model.freq_hz[count.reported()]:
        assert np.min(np.abs(exact / f - 1)) < 0.05
    if count.rule_refused:  # only a model the criterion preferred is said to be refused
        assert count.rule_refused[0] > 0
    reported = count.reported()
    assert without_column(count, reported, lambda f, x: True) == []
    refused = without_column(count, reported, lambda f, x: False)
    assert refused == count.model.freq_hz[reported].tolist() and refused
    notes = rule_notes(count, led.sensors)
    assert [n.code for n in notes] == ["model_inadequate"] and "stable column" in notes[0].message
    undecided = rule_notes(count, led.sensors, refused)
    assert [n.code for n in undecided] == ["model_inadequate"] + ["count_undecided"] * len(refused)
    assert [n.value for n in undecided[1:]] == refused


def test_where_the_model_is_adequate_the_rule_refuses_no_reported_mode(ride):
    count = _count(ride, 4)
    assert count.adequacy.adequate
    assert without_column(count, count.reported(), lambda f, x: False) == []
    assert rule_notes(count, ride.sensors, [5.0]) == []


def test_a_band_of_too_few_lines_is_not_shown_adequate_and_says_why(ride):
    """Ten lines, fewer than the method's window of 13: no noise to measure, so no ratio, the model is
    not shown adequate (the column rule holds), and the note says why instead of naming a sensor."""
    exact = am.supine_human().modes()
    data = DftLines.from_recording(ride, (10.0, 10.08))  # a line every 1/120 Hz: 10 lines
    model = fit_modal_model(data, exact.freq_hz[2:3], exact.damping[2:3], "zoh", 5, settings=DEFAULTS.dft)
    test = model_adequacy(model, data.u, LEVEL)
    assert data.u.size < 13 and np.all(np.isnan(test.ratio)) and not test.adequate
    count = SimpleNamespace(adequacy=test, rule_refused=(), model=model)
    notes = rule_notes(count, ride.sensors)
    assert len(notes) == 1 and notes[0].message.startswith("the band holds too few lines")
