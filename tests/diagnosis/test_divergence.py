"""A model whose simulation diverges judges nothing by simulation: a record of a system with a
pole just outside the unit circle (a growing oscillation, as a half-record fit of a short
earthquake record can hold: Painter Street, a pole at radius 1.0024 that grows 900 times over the
half it simulates) gets no fix confirmed on the simulation error, and the verdict says why. A root
that grows a few times over the half (an offset's or a trend's real root: 1.7-4.5) still simulates."""

import numpy as np
import pytest
from scipy.signal import lfilter

import armaxmodal as am
from armaxmodal.diagnosis import diagnose
from armaxmodal.diagnosis.inject import inject
from armaxmodal.diagnosis.model import DIVERGENT_GROWTH

RADIUS = 1.004  # a pole at 4 Hz of a 50 Hz record that grows 200 times over 1,350 samples


def _growing_ride() -> am.Recording:
    fs, n = 50.0, 2700
    rng = np.random.default_rng(5)
    u = rng.standard_normal(n)
    poles = [RADIUS * np.exp(2j * np.pi * 4.0 / fs), 0.97 * np.exp(2j * np.pi * 11.0 / fs)]
    a = np.real(np.poly(poles + [np.conj(p) for p in poles]))
    y = np.column_stack([lfilter([0.0, 1.0, 0.4], a, u), lfilter([0.0, 0.5, -0.3], a, u)])
    y += 0.02 * np.std(y, axis=0) * rng.standard_normal(y.shape)
    return am.Recording(fs, u, y, ("s1", "s2"))


def test_a_diverging_simulation_confirms_no_fix_judged_on_it():
    rec = inject(_growing_ride(), "periodic_disturbance", ["s1"], freq_hz=7.3, amp=0.2)
    d = diagnose(rec, max_rounds=1)
    assert d.baseline.held.growth > DIVERGENT_GROWTH and not d.baseline.held.simulates
    assert "held-out simulation diverges" in d.to_dict()["verdict"]
    assert not [e for e in d.effects if e.parameters["criterion"] == "held-out simulation error"]
    refused = [u for u in d.unconfirmed if "simulation, which diverges" in u["reason"]]
    assert any(u["effect"] == "periodic_disturbance" for u in refused)
    # the fits a diverging simulation would give are no fits: null in the JSON, "diverges" where read
    from armaxmodal.cli.diagnose import _diagnosis_text
    from armaxmodal.diagnosis.report import _fits_table

    report = d.to_dict()
    assert report["baseline"]["fit_val_pct"] == [None, None] and report["simulation_growth"]["baseline"] > 100
    assert _diagnosis_text("ride", report).count("diverges") >= 2
    assert set(_fits_table(report)["fit before (%)"]) == {"diverges"}
    from armaxmodal.diagnosis.plot import _fits

    assert set(_fits(d.baseline).values()) == {"diverges"}  # the figure's summary, too


def test_growth_is_the_fastest_unstable_mode_over_the_span_simulated():
    """``r^span`` of the largest root past 1 (the real root 1.0004 over 1,280 samples: 1.67, which
    still simulates), 1 when every root is inside."""
    from types import SimpleNamespace

    from armaxmodal.diagnosis.model import HeldOut, _growth

    def model(roots):
        return SimpleNamespace(fit=SimpleNamespace(models=[SimpleNamespace(a=np.real(np.poly(roots)))]))

    drift = [1.0004, 0.9 * np.exp(0.3j), 0.9 * np.exp(-0.3j)]
    assert _growth(model(drift), slice(1280, 2560)) == pytest.approx(1.0004**1280, rel=1e-6)
    assert _growth(model([0.99, 0.5]), slice(0, 5000)) == 1.0
    empty = np.zeros((1, 1))
    assert HeldOut(empty, empty, np.ones(1, bool), 4.5).simulates
    assert not HeldOut(empty, empty, np.ones(1, bool), 788.0).simulates


def test_a_fix_is_not_judged_against_a_diverging_baseline(fixtures_dir):
    """A refit that simulates beside a baseline that diverges: its simulation error is far lower
    for a reason that is not the fix, so the fix is refused all the same."""
    from dataclasses import replace

    from armaxmodal.diagnosis.acceptance import try_fix
    from armaxmodal.diagnosis.effects import entry_of, run_tests
    from armaxmodal.diagnosis.model import ModelSpec, Signals, fit_model, held_out
    from armaxmodal.diagnosis.result import Stage

    rec = inject(am.read_recording(fixtures_dir / "supine_random.csv"), "periodic_disturbance", ["head"],
                 freq_hz=11.3, amp=0.1)  # fmt: skip
    signals = Signals(rec.base, rec.response, rec.fs, rec.sensors, rec.input_name)
    spec = ModelSpec((10, 16, 10, -5))
    model = fit_model(spec, signals)
    stage = Stage(model, held_out(spec, signals, model))
    (line,) = [f for f in run_tests(model)[0] if f.effect == "periodic_disturbance"]
    entry = entry_of("periodic_disturbance")
    assert try_fix(stage, line, 0.01, entry)[0] is not None  # kept where the baseline simulates
    diverging = Stage(model, replace(stage.held, growth=10 * DIVERGENT_GROWTH))
    kept, reason = try_fix(diverging, line, 0.01, entry)
    assert kept is None and "diverges" in reason
