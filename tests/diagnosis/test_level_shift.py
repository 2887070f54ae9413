"""A sensor's offset that steps mid-record (issue 70): named ``level_shift`` on its sensor, its
time and size held by their intervals, taken out so the held-out error falls; told apart from a
drift; its statistic checked against a slow least-squares reference."""

import numpy as np
import pytest
from scipy.signal import lfilter

import armaxmodal as am
from armaxmodal.diagnosis import diagnose
from armaxmodal.diagnosis.inject import inject
from armaxmodal.diagnosis.level_shift import step_scan
from armaxmodal.exceptions import DataError

ORDERS = (10, 16, 10, -5)  # the supine fixture's orders chosen by BIC (README)


@pytest.fixture(scope="module")
def clean(fixtures_dir):
    return am.read_recording(fixtures_dir / "supine_random.csv")


def _run(rec, **kw):
    return diagnose(rec, baseline=am.fit_armax(rec, *ORDERS, shared_poles=True, warn=False), max_rounds=1, **kw)


@pytest.mark.parametrize(("channel", "time_s", "rms_share"), [("pelvis", 45.0, 0.3), ("head", 80.5, 0.15)])
def test_a_level_shift_is_named_placed_and_taken_out(clean, channel, time_s, rms_share):
    size = rms_share * float(np.std(clean.response[:, clean.sensors.index(channel)]))
    d = _run(inject(clean, "level_shift", [channel], time_s=time_s, size=size))
    (effect,) = d.effects
    assert effect.finding.effect == "level_shift" and effect.finding.channels == (channel,)
    p = effect.parameters
    lo, hi = p["time_ci95_s"]
    assert lo <= time_s <= hi and hi - lo < 1.0
    assert p["size_ci95"][0] <= size <= p["size_ci95"][1]
    assert p["sim_error_after"] < 0.9 * p["sim_error_before"]
    # the model's own step, completed by its refits, is the size reported (the first falls short)
    ((_, first, taken_out),) = d.final.model.spec.steps
    assert first == p["sample"] and abs(taken_out - p["size"]) < 0.25 * (p["size_ci95"][1] - p["size_ci95"][0])


def test_a_drift_is_not_a_level_shift(clean):
    """A drift of 0.004 per s leaves 3/4 of itself in the best step and all of it in the trend:
    the trend is named, and no step is tried."""
    d = _run(inject(clean, "offset_drift", ["chest"], drift_per_s=0.004))
    assert [e.finding.effect for e in d.effects] == ["offset_drift"]
    assert not [u for u in d.unconfirmed if u["effect"] == "level_shift"]


def test_the_step_statistic_is_the_least_squares_fit_of_the_step_pattern():
    """lambda(t0) and the size against a regression of the residual on the filtered step itself,
    one t0 at a time: a shift of the matched filter by one sample, or its energy taken over the
    wrong end, fails."""
    rng = np.random.default_rng(3)
    model = type("Model", (), {"a": np.array([1.0, -1.2, 0.5]), "c": np.array([1.0, -0.3])})()
    n = 400
    eps = rng.standard_normal(n)
    eps += 3.0 * lfilter(model.a, model.c, (np.arange(n) >= 150).astype(float))
    lam, size, sigma = step_scan(eps, model, np.ones(n, bool))
    for t0 in (0, 37, 150, 151, 399):
        z = lfilter(model.a, model.c, (np.arange(n) >= t0).astype(float))
        coef = (z @ eps) / (z @ z)
        assert size[t0] == pytest.approx(coef, rel=1e-9)
        assert lam[t0] == pytest.approx(coef * np.sqrt(z @ z) / sigma, rel=1e-9)
    assert int(np.argmax(np.abs(lam))) == 150 and size[150] == pytest.approx(3.0, abs=0.3)


def test_a_level_shift_outside_the_record_is_refused(clean):
    with pytest.raises(DataError, match="inside the record"):
        inject(clean, "level_shift", ["head"], time_s=clean.duration + 1, size=0.1)


def _fitted(eps, model):
    """What the level-shift test reads of a fitted model: one sensor, its ARMAX's A and C."""
    from types import SimpleNamespace

    return SimpleNamespace(signals=SimpleNamespace(n=eps.size, fs=50.0, sensors=("s",)),
                           spec=SimpleNamespace(shifts=(), trend_degree=2), fit=SimpleNamespace(models=(model,)))


@pytest.mark.parametrize("step", [0.0, 1.0])
def test_a_coloured_residual_is_no_level_shift_but_a_step_in_it_is(step):
    """An AR(1) residual (pole 0.9, as a misfit's slow wander) holds no step, but the white-noise
    bound names one (|lambda| far past its Bonferroni level); the residual's own spread of the
    sum (Newey-West) does not, and still finds a step of its size (5 of the wander's SDs)."""
    from armaxmodal.diagnosis.level_shift import level_shift_findings

    rng = np.random.default_rng(11)
    n, model = 6000, type("Model", (), {"a": np.array([1.0]), "c": np.array([1.0])})()
    wander = lfilter([1.0], [1.0, -0.9], rng.standard_normal(n))
    eps = wander + step * 5 * np.std(wander) * (np.arange(n) >= 2500)
    lam, _, _ = step_scan(eps, model, np.ones(n, bool))
    assert step or np.max(np.abs(lam)) > 8  # the white-noise bound would name it
    table = {}
    found = level_shift_findings(_fitted(eps, model), eps[:, None], np.ones(n, bool), 1, table)
    assert len(table["step_p"]) == 1
    if not step:
        assert table["step_p"][0] > 0.01  # run_tests keeps findings below 0.01 only
    else:
        (f,) = found
        assert f.channels == ("s",) and f.parameters["time_ci95_s"][0] <= 2500 / 50.0 <= f.parameters["time_ci95_s"][1]
        lo, hi = f.parameters["size_ci95"]
        assert lo <= 5 * np.std(wander) <= hi


def test_a_step_is_not_also_named_a_drift(clean):
    """A level shift told apart from a drift the other way: on a stepped ride the trend test,
    whose terms pass through A / C as the step's do, does not name the sensor (its p = 1 here:
    the ride's A nearly cancels a slow term), and the step test does."""
    from armaxmodal.diagnosis.effects import run_tests
    from armaxmodal.diagnosis.model import ModelSpec, Signals, fit_model

    rec = inject(clean, "level_shift", ["chest"], time_s=61.0, size=0.3 * float(np.std(clean.response[:, 1])))
    fitted = fit_model(ModelSpec(ORDERS), Signals(rec.base, rec.response, rec.fs, rec.sensors, rec.input_name))
    findings, table = run_tests(fitted)
    on_chest = [f.effect for f in findings if "chest" in f.channels]
    assert "level_shift" in on_chest and "offset_drift" not in on_chest
    assert table["step_p"][1] < 1e-6 < table["trend_p"][1]


def test_a_small_late_step_on_a_100_hz_record_is_found_past_the_start_up():
    """The Chapter 2 system at 100 Hz, a step of 0.1 x RMS on m3 at 91.75 s of 120 s, default
    baseline as a user runs it (the diagnosis battery's ride of seed 20261207): the predictor's
    start-up (its 1/C) outlasts the 2 % edge and read as a larger step at 2.48 s, and the planted
    one went unnamed."""
    u = am.random_vibration(100.0, 120.0, band=(0.5, 45.0), seed=20261207)
    ride = am.simulate_recording(am.chapter2_system(), u, 100.0, noise=0.05, seed=20261207 + 1000, hold="bandlimited")
    name = ride.sensors[2]
    size = 0.1 * float(np.std(ride.response[:, 2]))
    d = diagnose(inject(ride, "level_shift", [name], time_s=91.75, size=size), max_rounds=1)
    (effect,) = d.effects
    assert effect.finding.effect == "level_shift" and effect.finding.channels == (name,)
    lo, hi = effect.parameters["time_ci95_s"]
    assert lo <= 91.75 <= hi
    # the size's interval is conditional on the time found (here two samples late): 0.0846-0.0895
    # for a planted 0.0841, so held to 10 % only
    assert effect.parameters["size"] == pytest.approx(size, rel=0.1)


def test_a_step_on_a_late_sensor_is_placed_in_the_recorded_time(clean):
    """Pelvis 2 samples late and stepped at 45 s: the delay is moved first, then the step found in
    the moved frame is placed and taken out in the recorded one (sample 2700), its interval too."""
    late = inject(clean, "input_delay", ["pelvis"], samples=2.0)
    rec = inject(late, "level_shift", ["pelvis"], time_s=45.0, size=0.3)
    d = diagnose(rec, baseline=am.fit_armax(rec, *ORDERS, shared_poles=True, warn=False), max_rounds=2)
    assert [e.finding.effect for e in d.effects] == ["input_delay", "level_shift"]
    step = d.effects[1].parameters
    assert step["sample"] == 2700 and step["time_ci95_s"][0] <= 45.0 <= step["time_ci95_s"][1]
    assert d.final.model.spec.steps[0][:2] == ("pelvis", 2700)


def test_a_change_of_the_structure_is_no_level_shift():
    """Springs 12 % stiffer half way change every sensor's dynamics at 60 s, not one sensor's
    level: no step is named (the time-change test names it), and no gain change or clock drift."""
    from armaxmodal.diagnosis.effects import run_tests
    from armaxmodal.diagnosis.model import ModelSpec, Signals, fit_model
    from tests.diagnosis.test_diagnose import _two_regimes

    rec = _two_regimes(1.12)
    fitted = fit_model(ModelSpec(ORDERS), Signals(rec.base, rec.response, rec.fs, rec.sensors, rec.input_name))
    named = {f.effect for f in run_tests(fitted)[0]}
    assert "time_varying" in named and not named & {"level_shift", "gain_change", "clock_drift"}
