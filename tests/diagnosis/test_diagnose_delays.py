"""Delays in the diagnosis loop (issue 27), and the loop's own rules.

A delay is named by the phase slope; its fix moves the channel and fits again with ``nk``
and ``nb`` chosen again by BIC (the baseline's ``nk`` was chosen on the delayed data and
cannot reach the non-causal taps the moved data need). Outputs that lag alike are one
effect on the input. A late channel's filled start belongs to its delay. The rules a fix is
kept by, and the family size the test p-values are corrected for, are tested where a
plausible slip would change what the loop reports.
"""

from dataclasses import replace

import numpy as np
import pytest
from scipy import stats

import armaxmodal as am
from armaxmodal.diagnosis import acceptance, diagnose
from armaxmodal.diagnosis.delays import _common_delay, delay_findings
from armaxmodal.diagnosis.effects import REGISTRY, entry_of, run_tests
from armaxmodal.diagnosis.finding import Finding
from armaxmodal.diagnosis.inject import inject
from armaxmodal.diagnosis.model import ModelSpec, Signals, fit_model, fractional_shift, held_out, usable
from armaxmodal.diagnosis.result import Stage
from armaxmodal.prepare.delay import DelayEstimate, estimate_delays

ORDERS = (10, 16, 10, -5)  # the supine fixture's orders chosen by BIC


@pytest.fixture(scope="module")
def clean(fixtures_dir):
    return am.read_recording(fixtures_dir / "supine_random.csv")


def _model(rec, orders=ORDERS):
    signals = Signals(rec.base, rec.response, rec.fs, rec.sensors, rec.input_name)
    return fit_model(ModelSpec(orders), signals)


def _zero_filled_late(rec, names, samples: int):
    """``names`` recorded ``samples`` late, their first samples zero (a recorder's fill)."""
    y = rec.response.copy()
    for name in names:
        k = rec.sensors.index(name)
        y[samples:, k] = y[:-samples, k].copy()
        y[:samples, k] = 0.0
    return replace(rec, response=y)


def test_outputs_that_lag_alike_are_one_input_delay_confirmed_with_nk_chosen_again(clean):
    """Every body sensor 3 samples (50 ms) late, default baseline: before, each output was
    named and three of four ended 'unconfirmed' (refitted at the delayed data's nk). Now one
    effect on the input, its interval covering 50 ms, kept with nk moved by the delay."""
    late = inject(clean, "input_delay", list(clean.sensors), samples=3.0)
    d = diagnose(late)
    assert [(e.finding.effect, e.finding.channels) for e in d.effects] == [("input_delay", ("base",))]
    assert not [u for u in d.unconfirmed if u["effect"] == "input_delay"]
    p = d.effects[0].parameters
    assert p["delay_samples"] == pytest.approx(-3.0, abs=0.1)
    lo, hi = p["outputs_lag_ci95_ms"]
    assert lo < 50.0 < hi and hi - lo < 4.0
    assert p["nk_after"] == p["nk_before"] - 3 and p["nb_after"] == p["nb_before"] + 3
    assert "chosen again by BIC" in d.effects[0].note


def test_a_late_input_is_one_input_delay_of_the_other_sign(clean):
    """The input 3 samples late: every output leads alike, the input is named late by 3."""
    n_tests = len({e.test for e in REGISTRY}) * 4
    (f,) = delay_findings(_model(inject(clean, "input_delay", ["base"], samples=3.0)), n_tests)
    assert f.channels == ("base",) and f.parameters["delay_samples"] == pytest.approx(3.0, abs=0.1)
    assert f.parameters["outputs_lag_ci95_ms"][0] < -50.0 < f.parameters["outputs_lag_ci95_ms"][1]


def test_a_spread_of_delays_is_named_per_output(clean):
    spread = inject(
        inject(clean, "input_delay", ["head", "chest"], samples=2.0), "input_delay", ["pelvis", "legs"], samples=4.0
    )
    found = {f.channels[0]: f.parameters["delay_samples"] for f in delay_findings(_model(spread), 28)}
    assert found == pytest.approx({"head": 2.0, "chest": 2.0, "pelvis": 4.0, "legs": 4.0}, abs=0.1)


def _estimate(name, delay_ms, sd_ms, left_out=()):
    return DelayEstimate(name, delay_ms / 1e3, sd_ms / 1e3, 1, 40, 4.0, 30, tuple(v / 1e3 for v in left_out))


def test_the_common_delay_widens_for_a_spread_beyond_the_intervals_and_refuses_a_real_one():
    alike = [_estimate("a", 50.0, 0.4), _estimate("b", 50.2, 0.4)]
    common = _common_delay(alike, 60.0)
    assert common["lag_s"] == pytest.approx(0.0501, abs=1e-7)
    fixed_half = stats.t.ppf(0.975, 30) * 0.4 / np.sqrt(2) / 1e3
    assert np.diff(common["lag_ci95_s"])[0] / 2 == pytest.approx(fixed_half, rel=1e-6)
    # spread within chance but beyond the intervals (Q > K - 1): the random-effects interval is wider
    wider = _common_delay([_estimate("a", 49.0, 0.4), _estimate("b", 50.0, 0.4), _estimate("c", 50.3, 0.4)], 60.0)
    assert wider["spread_p"] > 0.01 and np.diff(wider["lag_ci95_s"])[0] / 2 > stats.t.ppf(0.975, 30) * 0.4e-3 / np.sqrt(
        3
    )
    # 2 and 4 samples apart at 60 Hz, each to 0.5 ms: two delays, not one
    assert _common_delay([_estimate("a", 33.3, 0.5), _estimate("b", 66.7, 0.5)], 60.0) is None
    # differences below the reporting floor are one delay even where the intervals exclude each other
    assert _common_delay([_estimate("a", 50.0, 0.01), _estimate("b", 50.5, 0.01)], 60.0) is not None
    # the outputs' shared noise: a jackknife over common blocks wider than the independent figure wins
    blocks = [50.0 + s for s in (-2.0, 2.0, -2.0, 2.0)]
    jack = _common_delay([_estimate("a", 50.0, 0.4, blocks), _estimate("b", 50.0, 0.4, blocks)], 60.0)
    assert jack["sd_s"] == pytest.approx(np.sqrt(3 / 4 * 4 * 4.0) / 1e3, rel=1e-9)


def test_a_zero_filled_late_start_is_the_delay_not_a_stuck_sensor(clean):
    """A channel that starts 3 samples late with zeros: before, the zeros were a stuck sensor
    on legs (and after the fix on head and chest too); they are the delay's."""
    d = diagnose(_zero_filled_late(clean, ["legs"], 3), baseline=am.fit_armax(clean, *ORDERS, warn=False))
    assert [(e.finding.effect, e.finding.channels) for e in d.effects] == [("input_delay", ("legs",))]
    assert not any(u["effect"] == "sensor_fault" for u in d.unconfirmed)
    # in the round that names the delay too, and for every output when the input names it
    found, _ = run_tests(_model(_zero_filled_late(clean, ["legs"], 3)))
    assert [(f.effect, f.channels) for f in found] == [("input_delay", ("legs",))]
    found, _ = run_tests(_model(_zero_filled_late(clean, list(clean.sensors), 3)))
    assert [(f.effect, f.channels) for f in found] == [("input_delay", ("base",))]
    # the same zeros without a delay to explain them are a stuck run
    y = clean.response.copy()
    y[:3, 3] = 0.0
    found, _ = run_tests(_model(replace(clean, response=y)))
    assert ("sensor_fault", ("legs",)) in [(f.effect, f.channels) for f in found]


def test_the_fractional_shift_never_wraps_the_end_onto_the_start():
    """A spike in the last samples must not appear at the start, either way; the samples a
    shift cannot know are outside every error."""
    x = np.zeros(400)
    x[-3:] = 100.0
    for samples in (2.5, -2.5, 3.0, -3.0):
        assert np.max(np.abs(fractional_shift(x, samples)[:200])) < 0.05
    mask = usable(400, ModelSpec((2, 3, 2, 0), shifts=(("y1", -2.5),)))
    assert not mask[:3].any() and not mask[-3:].any()


def _planted_line(clean):
    return inject(clean, "periodic_disturbance", ["head"], freq_hz=12.5, amp=0.1)


def test_a_fix_is_kept_only_when_the_held_out_test_and_bic_both_say_so(clean, monkeypatch):
    """The rule ``p < alpha and dBIC < 0``: a planted line is kept as measured; the same fix
    with the held-out test made to disagree is refused, and so is a useless richer noise model
    with the held-out test made to agree (BIC disagrees)."""
    rec = _planted_line(clean)
    stage = Stage(_model(rec), held_out(ModelSpec(ORDERS), _signals(rec)))
    findings, _ = run_tests(stage.model)
    line = next(f for f in findings if f.effect == "periodic_disturbance")
    kept, reason = acceptance.try_fix(stage, line, 0.01, entry_of(line.effect))
    assert kept is not None and kept[0].delta_bic < 0 and kept[0].dm_p < 0.01, reason
    monkeypatch.setattr(acceptance, "_held_out_p", lambda *a, **k: 0.5)
    assert acceptance.try_fix(stage, line, 0.01, entry_of(line.effect))[0] is None
    monkeypatch.setattr(acceptance, "_held_out_p", lambda *a, **k: 1e-9)
    plain = Stage(_model(clean), held_out(ModelSpec(ORDERS), _signals(clean)))
    noise = Finding("coloured_noise", ("head",), "breusch_godfrey_F", 10.0, 1e-9)
    refused, reason = acceptance.try_fix(plain, noise, 0.01, entry_of("coloured_noise"))
    assert refused is None and "but BIC rose by" in reason


def _signals(rec):
    return Signals(rec.base, rec.response, rec.fs, rec.sensors, rec.input_name)


def test_each_p_value_is_corrected_for_sensors_times_tests(clean):
    """A delay finding's p is the raw two-sided t p-value times tests x sensors: the family
    the level ``alpha`` holds for (with sensors alone, false alarms would rise tenfold)."""
    late = inject(clean, "input_delay", ["legs"], samples=1.0)
    e = next(e for e in estimate_delays(late) if e.channel == "legs")
    raw = 2 * stats.t.sf(abs(e.delay_s) / e.delay_sd_s, e.dof)
    found, _ = run_tests(_model(late))
    (f,) = [f for f in found if f.effect == "input_delay"]
    family = len({e.test for e in REGISTRY}) * len(clean.sensors)  # abs=0: p is far below approx's 1e-12
    assert f.p == pytest.approx(min(1.0, raw * family), rel=1e-9, abs=0)


def test_clean_rides_raise_no_alarm_at_the_corrected_level():
    """Six clean rides of another structure and rate, orders known: no effect named on any
    (at alpha = 0.01 family-wise, a false alarm on any of six has chance about 6 %)."""
    system = am.chapter2_system()
    alarms = []
    for seed in range(6):
        u = am.random_vibration(100.0, 40.0, band=(0.5, 45.0), seed=100 + seed)
        rec = am.simulate_recording(system, u, 100.0, noise=0.05, seed=200 + seed, hold="bandlimited")
        found, _ = run_tests(_model(rec, (10, 14, 10, -3)))  # chosen by BIC on seed 0
        alarms += [(seed, f.effect, f.channels, f.p) for f in found]
    assert not alarms


def test_real_stiff_one_storey_delay_is_confirmed_as_stabilise_times_it(realdata_dir):
    """The top IMU of the stiff 1-storey shake-table model lags the table by about 2.3
    samples (stabilise: 19.3 ms, 18.3-20.3). Before, diagnose left the delay unconfirmed
    (held-out 0.0784 -> 0.101 at the delayed data's nk = 0)."""
    from armaxmodal.io.xsens import read_xsens

    files = [str(realdata_dir / "mini_shake_table_imu" / "stiff1" / f"elcentro1__{s}.csv.gz") for s in ("g", "f1")]
    rec = read_xsens(files, input="g")
    d = diagnose(rec, max_rounds=1)
    (effect,) = d.effects
    assert effect.finding.effect == "input_delay" and effect.finding.channels == ("f1",)
    assert effect.parameters["delay_ms"] == pytest.approx(19.3, abs=1.0)
    assert effect.parameters["nk_after"] < effect.parameters["nk_before"]


def test_a_per_output_delay_finding_reports_the_phase_slope_estimate_as_it_is(clean):
    """The finding's numbers are the estimate's: ms, its Student-t interval, samples at fs;
    the statistic names the phase slope, which the keep rule reads."""
    late = inject(clean, "input_delay", ["legs"], samples=2.4)
    e = next(e for e in estimate_delays(late) if e.channel == "legs")
    (f,) = delay_findings(_model(late), 28)
    half = stats.t.ppf(0.975, e.dof) * e.delay_sd_s
    assert (f.effect, f.channels, f.statistic) == ("input_delay", ("legs",), "phase_slope_z")
    assert f.parameters["delay_ms"] == pytest.approx(1e3 * e.delay_s, rel=1e-12)
    assert f.parameters["delay_ci95_ms"] == pytest.approx([1e3 * (e.delay_s - half), 1e3 * (e.delay_s + half)])
    assert f.parameters["delay_samples"] == pytest.approx(e.delay_s * 60.0, rel=1e-12)
    assert f.value == pytest.approx(e.delay_s / e.delay_sd_s)


def test_a_lead_beyond_the_taps_is_reported_in_samples_and_ms_with_its_method(clean):
    from armaxmodal.diagnosis.delays import lead_findings

    ahead = inject(clean, "input_delay", ["legs"], samples=-14.0)
    legs = {f.channels[0]: f for f in lead_findings(_model(ahead), 28, set())}["legs"]
    assert (legs.effect, legs.statistic) == ("input_delay", "residual_input_ccf_z")
    assert legs.value > 30 and legs.p < 1e-6  # the correlation's z (60.9 here; p underflows to 0)
    assert legs.parameters["delay_ms"] == pytest.approx(1e3 * legs.parameters["delay_samples"] / 60.0, rel=1e-12)
    assert legs.parameters["method"] == "residual-input cross-correlation beyond the model's non-causal taps"


def test_the_common_delay_is_the_dersimonian_laird_mean_with_its_own_quantile():
    """Against the formulas written out here: Cochran's Q on K - 1 degrees of freedom, the
    between-output variance tau^2, the random-effects mean and its standard error, and a
    Student-t quantile on the estimates' fewest degrees of freedom (1 here: 12.7)."""
    d, sd = np.array([49.0, 50.0, 50.3]), np.array([0.4, 0.5, 0.3])
    est = [DelayEstimate(n, v / 1e3, s / 1e3, 1, 40, 4.0, 1) for n, v, s in zip("abc", d, sd, strict=True)]
    got = _common_delay(est, 60.0)
    w = 1 / sd**2
    q = np.sum(w * (d - np.sum(w * d) / w.sum()) ** 2)
    tau2 = (q - 2) / (w.sum() - np.sum(w**2) / w.sum())
    w_re = 1 / (sd**2 + tau2)
    mean, se = np.sum(w_re * d) / w_re.sum(), 1 / np.sqrt(w_re.sum())
    assert got["spread_p"] == pytest.approx(stats.chi2.sf(q, 2), rel=1e-12)
    assert 1e3 * got["lag_s"] == pytest.approx(mean, rel=1e-12) and 1e3 * got["sd_s"] == pytest.approx(se, rel=1e-12)
    half = stats.t.ppf(0.975, 1) * se
    assert 1e3 * np.array(got["lag_ci95_s"]) == pytest.approx([mean - half, mean + half], rel=1e-12)


def test_a_jackknife_over_three_blocks_counts_with_two_degrees_of_freedom():
    blocks = (47.0, 50.0, 53.0)
    got = _common_delay([_estimate("a", 50.0, 0.4, blocks), _estimate("b", 50.0, 0.4, blocks)], 60.0)
    jack = np.sqrt(2 / 3 * 18.0)
    assert 1e3 * got["sd_s"] == pytest.approx(jack, rel=1e-12)
    assert 1e3 * np.diff(got["lag_ci95_s"])[0] / 2 == pytest.approx(stats.t.ppf(0.975, 2) * jack, rel=1e-12)


def test_the_input_finding_carries_the_common_delay_both_ways(clean):
    """On the input: how late it is (negative: the outputs lag it) and, for the reader, the
    outputs' common lag with its interval and each output's own."""
    from armaxmodal.diagnosis.delays import _input_finding

    common = {"lag_s": 0.05, "sd_s": 0.001, "lag_ci95_s": [0.048, 0.052], "per_output_s": {"head": 0.049},
              "spread_p": 0.3}  # fmt: skip
    f = _input_finding(common, 1e-6, _model(clean).signals)
    assert (f.effect, f.channels, f.statistic, f.value, f.p) == ("input_delay", ("base",), "phase_slope_z", 50.0, 1e-6)
    expected = {"delay_ms": -50.0, "delay_ci95_ms": [-52.0, -48.0], "delay_samples": -3.0, "outputs_lag_ms": 50.0,
                "outputs_lag_ci95_ms": [48.0, 52.0], "spread_p": 0.3}  # fmt: skip
    assert set(f.parameters) == {*expected, "per_output_lag_ms"}
    assert f.parameters["per_output_lag_ms"] == pytest.approx({"head": 49.0})
    for key, value in expected.items():
        assert f.parameters[key] == pytest.approx(value), key


def test_the_delay_keep_rule_at_its_boundaries():
    """Kept unless the moved model is both worse by over 1 % and significantly so; the note
    says which of fell / no worse / not significantly worse, and the common lag."""
    params = {"nk_before": -2, "nk_after": -5}
    judge = acceptance._judge_delay
    assert judge(params, 1.0, 0.9, 0.001, 0.01)[0].endswith(
        "the held-out error fell (1 -> 0.9); the phase slope names and times the delay"
    )
    assert judge(params, 1.0, 1.0099, 0.5, 0.01)[0] == (
        "moved and refitted with nk -2 -> -5 chosen again by BIC, the held-out error is no worse (1 -> 1.01); "
        "the baseline's B taps had absorbed the delay, which the phase slope names and times"
    )
    assert ", the held-out error is not significantly worse (1 -> 1.01);" in judge(params, 1.0, 1.0101, 0.5, 0.01)[0]
    assert "is not significantly worse" in judge(params, 1.0, 1.05, 1 - 0.0101, 0.01)[0]
    note, reason = judge(params, 1.0, 1.05, 1 - 0.0099, 0.01)
    assert note == "" and "rose from 1 to 1.05 (p = 0.0099)" in reason and "nk -2 -> -5" in reason
    note, reason = judge(params, 1.0, 1.0099, 1 - 1e-6, 0.01)  # significant but within the refit's scatter
    assert reason == "" and "is no worse" in note
    alike = judge({**params, "outputs_lag_ms": 49.6, "spread_p": 0.095}, 1.0, 1.0, 0.5, 0.01)[0]
    assert alike.startswith("every output lags the input by 49.6 ms alike (spread p = 0.095)")


def test_the_moved_model_tries_nk_around_the_move_with_nb_keeping_the_causal_taps(clean, monkeypatch):
    """The candidates, their nb and their starts, recorded by a stand-in for the fit; the
    lowest BIC on the samples all candidates share wins."""
    base = _model(clean)
    tried = []

    class Stub:
        def __init__(self, spec, start):
            self.spec, self.start, self.signals = spec, start, base.signals

        def one_step_errors(self):
            # nk = -1 fits best by BIC's sum of per-output log variances, not by their pooled mean
            row = [1.0, 1.0, 1.0, 100.0] if self.spec.orders[3] == -1 else [10.0] * 4
            return np.tile(row, (clean.n_samples, 1))

    def record(spec, signals, start=None):
        tried.append((spec.orders, start))
        return Stub(spec, start)

    monkeypatch.setattr(acceptance, "fit_model", record)
    # a baseline at nk = 1 (a zero-order hold), nb = 1; the output 2 samples late is moved earlier
    spec = replace(base.spec, orders=(10, 1, 10, 1), shifts=(("legs", 2.0),))
    start = replace(base, spec=replace(spec, shifts=()))
    late = Finding("input_delay", ("legs",), "phase_slope_z", 9.0, 1e-9, {"delay_samples": 2.0})
    best = acceptance._moved_and_reordered(start, spec, late)
    assert [orders for orders, _ in tried] == [(10, 3, 10, -2), (10, 2, 10, -1), (10, 1, 10, 0), (10, 1, 10, 1)]
    assert [s is start for _, s in tried] == [False, False, False, True]
    assert best.spec.orders == (10, 2, 10, -1)
    # the input late by 2: the outputs move the other way, nk around 3
    tried.clear()
    early = Finding("input_delay", ("base",), "phase_slope_z", 9.0, 1e-9, {"delay_samples": 2.0})
    acceptance._moved_and_reordered(start, replace(spec, shifts=(("base", 2.0),)), early)
    assert [orders[3] for orders, _ in tried] == [1, 2, 3, 4]


def _findings_for(monkeypatch, clean, estimates, sensors=None):
    """``delay_findings`` on the clean ride's model with the phase-slope estimates given."""
    from armaxmodal.diagnosis import delays

    monkeypatch.setattr(delays, "estimate_delays", lambda rec: estimates)
    model = _model(clean)
    if sensors is not None:
        model = replace(model, signals=replace(model.signals, sensors=sensors, y=model.signals.y[:, : len(sensors)]))
    return delays.delay_findings(model, 28)


def test_only_outputs_late_or_early_alike_make_an_input_delay(clean, monkeypatch):
    wide = 5.0  # ms: intervals wide enough that the spread test passes
    late = [_estimate(n, 40.0, wide) for n in clean.sensors]
    assert [f.channels for f in _findings_for(monkeypatch, clean, late)] == [("base",)]
    early = [_estimate(n, -40.0, wide) for n in clean.sensors]
    assert [f.channels for f in _findings_for(monkeypatch, clean, early)] == [("base",)]
    # alike by the spread test (intervals of 80 ms), but one early and three late
    mixed = [_estimate(n, 20.0 if n != "head" else -20.0, 80.0) for n in clean.sensors]
    assert [f.channels for f in _findings_for(monkeypatch, clean, mixed)] == [(n,) for n in clean.sensors]
    # two outputs are enough; one output is its own
    two = [_estimate("head", 40.0, wide), _estimate("chest", 41.0, wide)]
    assert [f.channels for f in _findings_for(monkeypatch, clean, two, ("head", "chest"))] == [("base",)]
    one = [_estimate("head", 40.0, wide)]
    assert [f.channels for f in _findings_for(monkeypatch, clean, one, ("head",))] == [("head",)]
    # under the reporting floor (3/4 sample at 60 Hz, 12.5 ms) nothing is named
    assert _findings_for(monkeypatch, clean, [_estimate("head", 12.4, 0.1)], ("head",)) == []
    assert len(_findings_for(monkeypatch, clean, [_estimate("head", 12.6, 0.1)], ("head",))) == 1


def test_a_delay_p_value_is_two_sided_student_t_times_the_family(clean, monkeypatch):
    for dof, sd in ((3, 0.006), (1, 0.0001)):  # p = 0.10 and 0.036 after the factor 28
        e = DelayEstimate("head", 0.05, sd, 1, 40, 4.0, dof)
        (f,) = _findings_for(monkeypatch, clean, [e], ("head",))
        assert f.p == pytest.approx(2 * stats.t.sf(0.05 / sd, dof) * 28, rel=1e-12) and f.p < 0.2
    weak = DelayEstimate("head", 0.02, 0.05, 1, 40, 4.0, 3)
    (f,) = _findings_for(monkeypatch, clean, [weak], ("head",))
    assert f.p == 1.0


def test_late_start_counts_the_samples_each_delay_explains(clean):
    from armaxmodal.diagnosis.delays import late_start

    model = _model(clean)
    assert late_start(model, []) == {}
    moved = replace(model, spec=replace(model.spec, shifts=(("legs", 2.5),)))
    assert late_start(moved, []) == {"legs": 4}
    on_input = Finding("input_delay", ("base",), "phase_slope_z", 9.0, 1e-9, {"delay_samples": -0.5})
    assert late_start(moved, [on_input]) == {"head": 2, "chest": 2, "pelvis": 2, "legs": 4}
    input_late = Finding("input_delay", ("base",), "phase_slope_z", 9.0, 1e-9, {"delay_samples": 3.0})
    assert late_start(model, [input_late]) == {}


@pytest.mark.filterwarnings("error::UserWarning")
def test_the_figure_of_a_short_record_is_drawn(tmp_path, clean):
    """A 22 s record (the stiff 1-storey El Centro run is 21 s): the held-out trace window ran
    past the record's end and the CLI raised from matplotlib, writing nothing; the residual
    spectrum's segment was capped at n x K values, not n samples (scipy warned)."""
    from armaxmodal.cli import main
    from armaxmodal.io.write import write_recording_csv

    short = replace(clean, base=clean.base[:1300], response=clean.response[:1300])
    data, fig, out = tmp_path / "short.csv", tmp_path / "d.png", tmp_path / "d.json"
    write_recording_csv(short, data)
    assert main(["diagnose", str(data), "--plot", str(fig), "--json", str(out), "--quiet"]) == 0
    assert fig.stat().st_size > 10_000 and out.exists()


def test_a_lead_by_cross_correlation_waits_for_the_disturbances_a_phase_slope_delay_does_not():
    from armaxmodal.diagnosis.effects import tier_of

    slope = Finding("input_delay", ("legs",), "phase_slope_z", 9.0, 1e-9, {"delay_samples": 2.0})
    lead = Finding("input_delay", ("legs",), "residual_input_ccf_z", 9.0, 1e-9, {"delay_samples": -14.0})
    line = Finding("periodic_disturbance", ("head",), "harmonic_F", 9.0, 1e-9, {"freq_hz": 11.7})
    assert tier_of(slope) == 0 and tier_of(line) == 1 and tier_of(lead) == entry_of("coloured_noise").tier == 2
    assert sorted([lead, line, slope], key=tier_of) == [slope, line, lead]


def test_a_fix_is_judged_by_its_effects_own_keep_rule(clean):
    """An entry whose refit changes nothing (no significant drop, BIC unchanged): the general rule
    refuses it, the entry's own rule keeps it, and its note is the effect's."""
    from dataclasses import replace

    stage = Stage(_model(clean), held_out(ModelSpec(ORDERS), _signals(clean)))
    finding = Finding("clipping", ("head",), "rail_pileup", 12.0, 1e-9, {"samples": 12})
    same = replace(entry_of("clipping"), refit=lambda stage, finding, entry: stage, refuse=None)
    assert acceptance.try_fix(stage, finding, 0.01, replace(same, keep=acceptance.significant_drop))[0] is None
    kept, _ = acceptance.try_fix(stage, finding, 0.01, replace(same, keep=lambda j: (True, "its own rule")))
    assert kept is not None and kept[0].note == "its own rule"
