"""A sensor whose gain changes mid-record (issue 70): named ``gain_change`` on its sensor, its time
and factor held by their intervals, taken out so the held-out error falls; its statistic checked
against a slow least-squares reference. A step and a change of the structure are told from it by
their own tests (``test_level_shift.py``, ``test_diagnose.py``'s stiffening ride)."""

import numpy as np
import pytest

import armaxmodal as am
from armaxmodal.diagnosis import diagnose
from armaxmodal.diagnosis.gain_change import gain_scan
from armaxmodal.diagnosis.inject import inject
from armaxmodal.exceptions import DataError

ORDERS = (10, 16, 10, -5)  # the supine fixture's orders chosen by BIC (README)


@pytest.fixture(scope="module")
def clean(fixtures_dir):
    return am.read_recording(fixtures_dir / "supine_random.csv")


@pytest.mark.parametrize(("channel", "time_s", "factor"), [("pelvis", 50.0, 1.2), ("head", 80.25, 0.9)])
def test_a_gain_change_is_named_placed_and_taken_out(clean, channel, time_s, factor):
    rec = inject(clean, "gain_change", [channel], time_s=time_s, factor=factor)
    d = diagnose(rec, baseline=am.fit_armax(rec, *ORDERS, shared_poles=True, warn=False), max_rounds=1)
    (effect,) = d.effects
    assert effect.finding.effect == "gain_change" and effect.finding.channels == (channel,)
    p = effect.parameters
    assert p["time_ci95_s"][0] <= time_s <= p["time_ci95_s"][1] and p["time_ci95_s"][1] - p["time_ci95_s"][0] < 1
    assert p["factor_ci95"][0] <= factor <= p["factor_ci95"][1]
    # the first reading falls short (the model fitted with the change carried part of it); the refits
    # complete it, and the model's own factor is the one reported
    assert abs(p["factor_first"] - 1) < abs(factor - 1)
    ((_, first, taken_out),) = d.final.model.spec.gains
    assert first == p["sample"] and abs(taken_out - p["factor"]) < p["factor_ci95"][1] - p["factor_ci95"][0]
    # the interval: the SD of what the residual still shows, over the share of a change it shows
    from armaxmodal.diagnosis.fixes import seen_share
    from armaxmodal.diagnosis.gain_change import remaining_gain
    from armaxmodal.stats import Z95

    _, sd = remaining_gain(d.final.model, channel, first)
    share = seen_share(p["factor_first"] - 1, p["factor"] - 1)
    assert 0.3 < share < 0.9  # about half of the change is carried by the model fitted with it
    assert np.ptp(p["factor_ci95"]) / 2 == pytest.approx(p["factor"] * Z95 * sd / share, rel=1e-9)
    assert p["sim_error_after"] < 0.9 * p["sim_error_before"]


def test_the_gain_statistic_is_the_least_squares_fit_of_the_scaled_output():
    """The relative change and lambda at each t0 against a regression of the residual on the
    predicted part from t0 on, one t0 at a time: sums taken from the wrong end fail."""
    rng = np.random.default_rng(4)
    n = 500
    z = np.sin(np.arange(n) / 3.0) + 0.3 * rng.standard_normal(n)
    eps = rng.standard_normal(n) + 2.0 * z * (np.arange(n) >= 300)
    lam, d, energy = gain_scan(eps, z, np.ones(n, bool))
    sigma = 1.4826 * float(np.median(np.abs(eps - np.median(eps))))  # the residual's robust SD, by hand
    for t0 in (0, 99, 300, 499):
        x = np.where(np.arange(n) >= t0, z, 0.0)
        coef = (x @ eps) / (x @ x)
        assert d[t0] == pytest.approx(coef, rel=1e-9) and energy[t0] == pytest.approx(x @ x, rel=1e-12)
        assert lam[t0] == pytest.approx(coef * np.sqrt(x @ x) / sigma, rel=1e-4)
    assert abs(int(np.argmax(np.abs(lam))) - 300) <= 3


def test_a_gain_change_planted_wrongly_is_refused(clean):
    with pytest.raises(DataError, match="factor must be > 0"):
        inject(clean, "gain_change", ["head"], time_s=10.0, factor=0.0)
    with pytest.raises(DataError, match="inside the record"):
        inject(clean, "gain_change", ["head"], time_s=-1.0, factor=1.1)


def test_a_change_every_sensor_shows_is_the_structure_not_a_gain():
    """Springs 12 % stiffer half way: each sensor's response changes at once, and the gain scan of
    a sensor fires (a chest 'gain change' was kept ahead of the time change); another sensor
    changing at the same time makes it the structure's, and no gain change is named."""
    from armaxmodal.diagnosis.effects import run_tests
    from armaxmodal.diagnosis.model import ModelSpec, Signals, fit_model
    from tests.diagnosis.test_diagnose import _two_regimes

    rec = _two_regimes(1.12)
    fitted = fit_model(ModelSpec(ORDERS), Signals(rec.base, rec.response, rec.fs, rec.sensors, rec.input_name))
    findings, table = run_tests(fitted)
    assert min(table["gain_p"]) < 0.01 and not [f for f in findings if f.effect == "gain_change"]


def test_the_interval_widens_by_the_share_of_the_change_the_residual_shows():
    """A model fitted with the change in the data carries part of it, so the residual shows only a
    share of what remains: the first reading over the completed total (0.054 of 0.1). A first
    reading past the total (a drift's first-order overshoot), of the other sign or of no total
    leaves the SD as it is."""
    from armaxmodal.diagnosis.fixes import seen_share

    assert seen_share(0.054, 0.1) == pytest.approx(0.54)
    assert seen_share(-0.046, -0.1) == pytest.approx(0.46)
    assert seen_share(322.0, 278.0) == 1.0 and seen_share(-0.01, 0.1) == 1.0 and seen_share(0.01, 0.0) == 1.0
