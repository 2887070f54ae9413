"""Quality checks and preparation against defects planted with known size in the fixtures."""

import re
import warnings

import numpy as np
import pytest
import scipy.stats

import armaxmodal as am
from armaxmodal.exceptions import DataError
from armaxmodal.modes.diagram import stabilisation_diagram
from armaxmodal.modes.pipeline import select_modes
from armaxmodal.prepare.checks import check_quality
from armaxmodal.prepare.delay import estimate_delays
from armaxmodal.prepare.preparation import check_band, prepare
from armaxmodal.spectra import excited_band

FIXTURES = ["supine_random", "supine_sweep", "supine_random_zoh", "chapter2_random_zoh"]
# a delay estimate is right when it is within this many samples of the planted one
DELAY_SAMPLES_ATOL = 0.15
# the targets of automatic selection (README): 2 % in frequency, 10 % in damping
FREQ_RTOL, DAMPING_RTOL = 0.02, 0.10


@pytest.fixture(scope="module")
def clean(fixtures_dir):
    return am.read_recording(fixtures_dir / "supine_random.csv")


def _with(rec, base=None, response=None, sensors=None):
    return am.Recording(
        rec.fs,
        rec.base if base is None else base,
        rec.response if response is None else response,
        rec.sensors if sensors is None else sensors,
    )


def _late(x, samples):
    """``x`` recorded ``samples`` late: each value appears that many samples later. The
    unknown first samples are the record's next ones mirrored (a constant pad would be a
    run of equal samples, which the stuck-samples check rightly names)."""
    return np.concatenate([x[samples:0:-1], x[:-samples]])


def _codes(warnings):
    return [(w.code, w.channels) for w in warnings]


@pytest.mark.parametrize("name", FIXTURES)
def test_clean_fixtures_raise_no_warning(fixtures_dir, name):
    """No false alarm: band-limited and held inputs (a hold shows half a sample on every
    output, which is not a sensor defect)."""
    rec = am.read_recording(fixtures_dir / f"{name}.csv")
    assert check_quality(rec) == []
    assert prepare(rec).warnings == ()


@pytest.mark.parametrize("samples", [1, 2, 4])
def test_a_late_sensor_is_measured_named_and_aligned(clean, samples):
    y = clean.response.copy()
    y[:, 2] = _late(y[:, 2], samples)
    rec = _with(clean, response=y)
    delays = {e.channel: e for e in estimate_delays(rec)}
    est = delays["pelvis"]
    assert est.delay_s * rec.fs == pytest.approx(samples, abs=DELAY_SAMPLES_ATOL)
    assert abs(est.delay_s - samples / rec.fs) < 3 * est.delay_sd_s + DELAY_SAMPLES_ATOL / rec.fs
    # the others are on time
    assert all(abs(delays[s].delay_s * rec.fs) < 0.5 for s in ("head", "chest", "legs"))
    prep = prepare(rec)
    assert _codes(prep.warnings) == [("sensor_delay", ("pelvis",))]
    assert "lags" in prep.warnings[0].message and "Aligned" in prep.warnings[0].message
    assert prep.shifts == {"pelvis": samples}
    # aligned: the pelvis channel is the clean one again (mean removed), trimmed at the end
    n = prep.recording.n_samples
    assert n == clean.n_samples - samples
    want = clean.response[:n, 2] - clean.response[:, 2].mean()
    np.testing.assert_allclose(prep.recording.channel("pelvis")[samples:], want[samples:], atol=0.02 * want.std())


def test_the_delay_interval_matches_the_scatter_over_independent_rides():
    """The delay's standard deviation says how far it scatters: over 40 independent rides of
    a clean two-sensor chain (60 s, 50 Hz, held input) the mean squared standardised
    deviation from the rides' mean delay is near 1 (measured 1.06 and 1.07). The fit's own
    standard deviation alone treats correlated Welch lines as independent and read 1.68 and
    2.54: the warning's intervals were 1.3-1.6x too narrow."""
    chain = am.Structure.from_chain([10.0, 5.0], [8000.0, 0.0], [40.0, 0.0], [12000.0], [20.0], ("m1", "m2"))
    estimates = []
    for seed in range(40):
        ride = am.random_vibration(50.0, 60.0, (0.5, 24.0), seed=seed)
        rec = am.simulate_recording(chain, ride, 50.0, noise=0.05, seed=100 + seed)
        estimates.append([(e.delay_s, e.delay_sd_s, e.dof) for e in estimate_delays(rec)])
    delay, sd, dof = np.moveaxis(np.array(estimates), 2, 0)
    z2 = ((delay - delay.mean(axis=0)) / sd) ** 2
    assert np.all(z2.mean(axis=0) > 0.6) and np.all(z2.mean(axis=0) < 1.5), z2.mean(axis=0)
    assert np.all(dof >= 2)  # a Student-t quantile needs them; the sd has only a few
    # the held input's half sample on both sensors, which is no defect
    assert np.allclose(delay.mean(axis=0) * 50.0, 0.5, atol=0.1)


def test_the_printed_delay_interval_uses_the_t_quantile(clean):
    """The warning's 95 % interval is the estimate +- t(0.975, dof) standard deviations."""
    y = clean.response.copy()
    y[:, 2] = _late(y[:, 2], 2)
    rec = _with(clean, response=y)
    est = {e.channel: e for e in estimate_delays(rec)}["pelvis"]
    warning = [w for w in check_quality(rec) if w.code == "sensor_delay"][0]
    lo, hi = (float(v) for v in re.search(r"95 % interval ([-\d.]+) to ([-\d.]+) ms", warning.message).groups())
    half = est.quantile(0.975) * est.delay_sd_s * 1e3
    # few degrees of freedom: wider than the normal quantile
    assert est.quantile(0.975) == pytest.approx(scipy.stats.t.ppf(0.975, est.dof), rel=1e-9)
    assert lo == pytest.approx(1e3 * est.delay_s - half, abs=0.06)
    assert hi == pytest.approx(1e3 * est.delay_s + half, abs=0.06)


def test_a_late_input_is_named_as_the_input(clean):
    rec = _with(clean, base=_late(clean.base, 3))
    prep = prepare(rec)
    assert _codes(prep.warnings) == [("sensor_delay", ("base",))]
    assert prep.warnings[0].value == pytest.approx(3e3 / rec.fs, abs=DELAY_SAMPLES_ATOL * 1e3 / rec.fs)
    assert prep.shifts == {"base": 3}


def test_an_inverted_sensor_is_named(clean):
    y = clean.response.copy()
    y[:, 1] *= -1
    found = check_quality(_with(clean, response=y))
    assert _codes(found) == [("inverted_sensor", ("chest",))]


def test_an_inverted_input_is_named_not_every_output(clean):
    """The base channel's sign flipped: every output reads -1, which one flip on the input
    explains. Two outputs flipped of four are two sensors."""
    found = check_quality(_with(clean, base=-clean.base))
    assert _codes(found) == [("inverted_sensor", ("base",))] and "the input 'base'" in found[0].message
    y = clean.response.copy()
    y[:, :2] *= -1
    assert _codes(check_quality(_with(clean, response=y))) == [("inverted_sensor", ("head", "chest"))]


@pytest.mark.parametrize("scale", [1.0, -2.5, 9.81])
def test_a_duplicated_channel_is_named_and_left_out(clean, scale):
    y = np.column_stack([clean.response, scale * clean.response[:, 0] + 0.3])
    rec = _with(clean, response=y, sensors=(*clean.sensors, "head_copy"))
    prep = prepare(rec)
    dup = [w for w in prep.warnings if w.code == "duplicate_channel"]
    assert [w.channels for w in dup] == [("head_copy", "head")]
    assert f"{scale:.6g}" in dup[0].message or scale == 1.0
    assert prep.recording.sensors == clean.sensors and prep.dropped == ("head_copy",)


def test_an_output_equal_to_the_input_is_a_duplicate(clean):
    y = np.column_stack([clean.response, clean.base])
    rec = _with(clean, response=y, sensors=(*clean.sensors, "platform"))
    assert [w.channels for w in check_quality(rec) if w.code == "duplicate_channel"] == [("platform", "base")]
    with pytest.raises(DataError, match="nothing independent"):
        prepare(_with(clean, response=clean.base[:, None], sensors=("platform",)))


def test_a_clipped_channel_is_named(clean):
    y = clean.response.copy()
    rail = 0.6 * y[:, 3].max()
    y[:, 3] = np.minimum(y[:, 3], rail)
    found = check_quality(_with(clean, response=y))
    assert _codes(found) == [("clipping", ("legs",))]
    stuck = np.count_nonzero(y[:, 3] == rail)
    assert found[0].value == pytest.approx(100 * stuck / y.shape[0], rel=0.2)


def test_clipped_peaks_that_never_dwell_are_named_by_their_pile_up(clean):
    """Sampled a few times per period, a clipped peak is one sample at the rail, never two in
    a row; the pile-up at the rail (43 samples where the values just inside occur once each)
    names it. The channel under a coarse quantiser (every level visited often, its extreme
    ones two in a row) is not clipped, nor is one with 4 samples at the rail."""
    y = clean.response.copy()
    head = clean.response[:, 0]
    rail = np.sort(head)[-40]
    y[:, 0] = np.minimum(head, rail)
    at = y[:, 0] == rail
    assert not np.any(at[1:] & at[:-1])  # the dwell test alone would miss it
    (w,) = check_quality(_with(clean, response=y))
    assert (w.code, w.channels) == ("clipping", ("head",))
    assert w.value == pytest.approx(100 * (40 + 1) / y.shape[0])
    assert "40 on one, where the values just inside it occur about 1.0 times each" in w.message
    quantised, legs = clean.response.copy(), clean.response[:, 3]
    quantised[:, 3] = np.round(legs / np.std(legs)) * np.std(legs)  # a 1-sigma step
    top = quantised[:, 3] == quantised[:, 3].max()
    assert np.count_nonzero(top) > 40 and np.any(top[1:] & top[:-1])  # the dwell test alone flagged it
    assert not [w for w in check_quality(_with(clean, response=quantised)) if w.code == "clipping"]
    held = clean.response.copy()
    held[:, 0] = np.minimum(head, np.sort(head)[-6])
    peak = int(np.argmax(head))
    held[peak + 1, 0] = held[peak, 0]  # 7 at the rail, two in a row: p ~ 1e-4, named as a dwell
    (w,) = [w for w in check_quality(_with(clean, response=held)) if w.code == "clipping"]
    assert w.channels == ("head",) and "some in a row" in w.message
    for k in (4, 6):  # below CLIP_MIN_SAMPLES; six apart (p 6e-4) as likely as a peak visited twice
        few = clean.response.copy()
        few[:, 0] = np.minimum(head, np.sort(head)[-k])
        apart = few[:, 0] == few[:, 0].max()
        assert not np.any(apart[1:] & apart[:-1])
        assert not [w for w in check_quality(_with(clean, response=few)) if w.code == "clipping"]
    floor = clean.response.copy()
    floor[:, 0] = np.maximum(head, np.sort(head)[7])  # 8 at the minimum, apart: p 1e-5
    (w,) = [w for w in check_quality(_with(clean, response=floor)) if w.code == "clipping"]
    assert "8 on one" in w.message and "p = 1.0e-05" in w.message


def test_a_sine_ride_is_narrowband(clean):
    t = clean.time
    base = np.sin(2 * np.pi * 3.0 * t) + 0.01 * clean.base
    structure = am.supine_human()
    rec = am.simulate_recording(structure, base, clean.fs, noise=0.05, seed=3)
    found = check_quality(rec)
    assert [w.code for w in found] == ["check_not_run", "narrowband_input", "check_not_run"]
    assert "3.00 Hz" in found[1].message
    # a sine has no quasi-static lines: the checks that need them say they did not run
    outputs = ", ".join(rec.sensors)
    assert found[0].message.startswith(f"sensor_delay and inverted_sensor not tested on {outputs}:")
    assert found[2].message.startswith(f"unit_mismatch not tested on {outputs}:")


def test_offsets_and_drift_are_removed_and_reported(clean):
    t = clean.time
    y = clean.response + 9.81 + 0.02 * t[:, None]
    rec = _with(clean, response=y)
    mean_only = prepare(rec)
    assert [w.code for w in mean_only.warnings] == ["offset_removed", "drift"]
    assert mean_only.warnings[1].channels == clean.sensors and "+0.02/s" in mean_only.warnings[1].message
    np.testing.assert_allclose(mean_only.recording.response.mean(axis=0), 0, atol=1e-9)
    linear = prepare(rec, detrend="linear")
    assert [w.code for w in linear.warnings] == ["offset_removed", "trend_removed"]
    assert "+0.02/s" in linear.warnings[1].message
    np.testing.assert_allclose(linear.recording.response, clean.response - clean.response.mean(0), atol=0.05)


@pytest.mark.parametrize("size", [0.8, 0.28])
def test_a_sensor_offset_jumping_mid_record_is_found_removed_and_the_modes_kept(clean, size):
    """A pelvis offset jumping at t = 60 s (a sensor re-zeroing, a cable knock): before, +0.8
    moved the third mode from 13.7 to 14.7 Hz, outside its interval, with only a drift
    warning whose advice (--detrend linear) left it at 14.6 Hz; +0.28 (0.3 x RMS) lost it."""
    y = clean.response.copy()
    at = clean.n_samples // 2
    y[at:, 2] += size
    prepared = prepare(_with(clean, response=y))
    (step,) = [w for w in prepared.warnings if w.code == "offset_step"]
    assert step.channels == ("pelvis",) and "drift" not in [w.code for w in prepared.warnings]
    found = re.search(r"pelvis ([+-][0-9.]+) \(.*\) at t = ([0-9.]+) s", step.message)
    assert float(found[1]) == pytest.approx(size, abs=0.03) and float(found[2]) == pytest.approx(at / clean.fs, abs=0.1)
    # removed: the prepared pelvis is the clean one, centred, up to the estimated size of the
    # shift and the few samples by which its place may be missed
    expected = clean.response[:, 2] - clean.response[:, 2].mean()
    error = np.abs(prepared.recording.response[:, 2] - expected)
    assert np.median(error) < 0.01 and np.sum(error > 0.05) <= 6
    selection = select_modes(stabilisation_diagram(_with(clean, response=y), per_sensor=False))
    truth = am.supine_human().modes()
    assert len(selection.modes) == 4
    np.testing.assert_allclose(selection.modes.freq_hz, truth.freq_hz, rtol=FREQ_RTOL)


@pytest.mark.parametrize("where", [0.1, 0.5, 0.9])
def test_level_shifts_are_located_and_sized_a_drift_is_not_one(clean, where):
    from armaxmodal.prepare.detrend import level_shifts

    x = clean.response[:, 1].copy()
    at = int(where * x.size)
    shifted = x.copy()
    shifted[at:] += 0.5
    # located to a few samples: the oscillation about the shift blurs where it happened
    (found,) = level_shifts(shifted)
    assert abs(found[0] - at) <= 6 and found[1] == pytest.approx(0.5, abs=0.03)
    # down at 40 s and up again at 80 s: both, each with its size
    pulse = x.copy()
    pulse[2400:4800] -= 0.6
    (k1, j1), (k2, j2) = level_shifts(pulse)
    assert abs(k1 - 2400) <= 30 and abs(k2 - 4800) <= 30
    assert j1 == pytest.approx(-0.6, abs=0.05) and j2 == pytest.approx(0.6, abs=0.05)
    # a bare step: its exact sample and size
    assert level_shifts(np.r_[np.zeros(500), np.ones(700)]) == [(500, 1.0)]
    # a drift of the same size, a clean channel, and a velocity (the channel integrated: slow
    # wander whose best breakpoints explain 4-9 % of its variance, but none is sudden): none
    assert level_shifts(x + 0.5 * np.linspace(0.0, 1.0, x.size)) == []
    assert level_shifts(x) == []
    velocity = np.cumsum(x - x.mean()) / clean.fs
    assert level_shifts(velocity - np.linspace(velocity[0], velocity[-1], x.size)) == []


def test_a_level_shift_is_reported_not_removed_without_detrending(clean):
    y = clean.response.copy()
    y[3000:, 0] -= 0.5
    prepared = prepare(_with(clean, response=y), detrend="none")
    (step,) = prepared.warnings
    assert step.code == "offset_step" and step.channels == ("head",) and "not removed" in step.message
    np.testing.assert_array_equal(prepared.recording.response, y)


@pytest.mark.parametrize(
    "band, match",
    [((5.0, 2.0), "lo < hi"), ((float("nan"), 5.0), "finite"), ((2.0, 40.0), "Nyquist"), ((-1.0, 5.0), "lo < hi")],
)
def test_bad_bands_are_refused_at_once(clean, band, match):
    with pytest.raises(DataError, match=match):
        check_band(band, clean.fs)
    with pytest.raises(DataError, match=match):
        stabilisation_diagram(clean, band=band)


def test_gravity_and_a_late_sensor_still_give_the_four_modes(clean):
    """The damaged ride of the README's check: +9.81 on every sensor, one sensor 2 samples
    late. Before preparation the 13.5 Hz mode was lost without a word."""
    y = clean.response + 9.81
    y[:, 0] = _late(y[:, 0], 2)
    selection = select_modes(stabilisation_diagram(_with(clean, response=y), per_sensor=False))
    assert {w.code for w in selection.warnings} == {"offset_removed", "sensor_delay"}
    truth = am.supine_human().modes()
    assert len(selection.modes) == 4
    np.testing.assert_allclose(selection.modes.freq_hz, truth.freq_hz, rtol=FREQ_RTOL)
    np.testing.assert_allclose(selection.modes.damping, truth.damping, rtol=DAMPING_RTOL)
    js = selection.to_dict()
    assert {w["code"] for w in js["warnings"]} == {"offset_removed", "sensor_delay"}
    assert js["preprocessing"]["shifts_samples"] == {"head": 2}


def test_identify_prepares_the_record_too(clean):
    """``identify`` with fixed orders on the gravity-and-lag ride: without preparation its
    modes moved to 3.8 / 14.4 / 17.1 Hz with fits of -800 %; now the truth's, and it says why."""
    y = clean.response + 9.81
    y[:, 0] = _late(y[:, 0], 2)
    result = am.identify(_with(clean, response=y), (10, 16, 10, -5))
    truth = am.supine_human().modes()
    np.testing.assert_allclose(result.modes.freq_hz, truth.freq_hz, rtol=FREQ_RTOL)
    np.testing.assert_allclose(result.modes.damping, truth.damping, rtol=DAMPING_RTOL)
    js = result.to_dict()
    assert {w["code"] for w in js["warnings"]} == {"offset_removed", "sensor_delay"}
    assert js["preprocessing"]["shifts_samples"] == {"head": 2}
    assert js["analysis_fs"] == js["fs"] == clean.fs  # fixed orders keep the record's rate


def test_a_record_sampled_far_above_its_band_is_resampled_and_its_modes_found():
    """At 400 Hz with the excitation and modes below 20 Hz, low orders could not resolve the
    modes; the analysis runs at 57 Hz."""
    structure = am.supine_human()
    fs = 400.0
    u = am.random_vibration(fs, 60.0, (0.5, 20.0), seed=5)
    rec = am.simulate_recording(structure, u, fs, noise=0.05, hold="bandlimited", seed=6)
    diagram = stabilisation_diagram(rec, per_sensor=False)
    # the largest whole factor that keeps the excited band (to -30 dB, a little above 20 Hz
    # by leakage) under 0.4 of the new rate
    analysis_fs = diagram.preparation.analysis_fs
    band_hi = excited_band(rec)[1]
    assert fs / analysis_fs == int(0.4 * fs / band_hi) and analysis_fs <= fs / 4
    assert [w.code for w in diagram.warnings] == ["resampled"]
    selection = select_modes(diagram)
    truth = structure.modes()
    assert len(selection.modes) == 4
    np.testing.assert_allclose(selection.modes.freq_hz, truth.freq_hz, rtol=FREQ_RTOL)
    np.testing.assert_allclose(selection.modes.damping, truth.damping, rtol=DAMPING_RTOL)


@pytest.mark.parametrize(("n", "factor"), [(74000, 10), (1000, 2), (1001, 3), (999, 7), (5003, 4), (400, 5)])
def test_decimate_equals_scipy_resample_poly_on_the_samples_kept(n, factor):
    """prepare's own decimator (no scipy.signal import) against scipy's polyphase resampler,
    on a drifting random walk whose ends differ: the kept samples never see scipy's padding."""
    from scipy.signal import resample_poly

    from armaxmodal.prepare.resample import RESAMPLE_EDGE, decimate

    rng = np.random.default_rng(n)
    x = rng.standard_normal((n, 3)).cumsum(axis=0) + np.linspace(0.0, 50.0, n)[:, None]
    expected = resample_poly(x, 1, factor, axis=0, padtype="line")[RESAMPLE_EDGE:-RESAMPLE_EDGE]
    got = decimate(x, factor)
    assert got.shape == expected.shape
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12 * np.abs(expected).max())


def test_f16_torsion_mode_softens_and_damps_with_force(realdata_dir):
    """F-16 GVT benchmark (Noël & Schoukens): at 400 Hz with its modes in 2-15 Hz. The
    benchmark note's check gives the wing-torsion mode at 7.32 Hz, about 0.5 %, at level 1
    and 7.18 Hz, about 2 %, at level 7; wing bending near 5.2 Hz."""
    found = {}
    for level in (1, 7):
        rec = am.read_recording(
            realdata_dir / "f16_gvt" / f"F16Data_FullMSine_Level{level}.mat",
            input="Force",
            outputs=["Acceleration_1", "Acceleration_2", "Acceleration_3"],
        )
        diagram = stabilisation_diagram(rec, range(2, 51, 2), per_sensor=False)
        assert diagram.preparation.analysis_fs < 60
        modes = select_modes(diagram).modes
        torsion = modes.iloc[int(np.argmin(np.abs(modes.freq_hz - 7.25)))]
        found[level] = torsion
        assert (np.abs(modes.freq_hz / 5.2 - 1) < 0.03).any()
    assert found[1].freq_hz == pytest.approx(7.32, rel=0.005)
    assert 0.003 < found[1].damping < 0.008
    assert found[7].freq_hz == pytest.approx(7.18, rel=0.01)
    assert found[7].damping > 2.5 * found[1].damping


def test_outputs_that_do_not_respond_to_the_input_are_named(clean):
    """Independent noise in place of a sensor reads a coherence with the input near the
    estimate's bias (0.07); the clean ride's sensors read 0.78-1.00 and give no warning. When
    no output responds, the message says the modes found are not the structure's (a record of
    pure noise once gave two 'modes' with intervals and no warning)."""
    from armaxmodal.prepare.quality import INCOHERENT, input_coherence

    assert [w for w in check_quality(clean) if w.code == "incoherent_output"] == []
    coherence = input_coherence(clean.base, clean.response, clean.fs)
    assert coherence.min() > 0.75 > INCOHERENT
    rng = np.random.default_rng(1)
    y = clean.response.copy()
    y[:, 2] = rng.standard_normal(clean.n_samples)
    (w,) = [w for w in check_quality(_with(clean, response=y)) if w.code == "incoherent_output"]
    assert w.channels == ("pelvis",) and w.value < 0.1 and "pelvis 0.0" in w.message
    assert "do not respond" in w.message
    noise = rng.standard_normal(clean.response.shape)
    (w,) = [w for w in check_quality(_with(clean, response=noise)) if w.code == "incoherent_output"]
    assert w.channels == clean.sensors and "not the structure's" in w.message
    # the weighting is the input's spectrum: a response sensor's coherence, computed by scipy
    from scipy.signal import coherence as scipy_coherence
    from scipy.signal import welch

    f, c = scipy_coherence(clean.base, clean.response[:, 0], clean.fs, nperseg=clean.n_samples // 8)
    _, puu = welch(clean.base, clean.fs, nperseg=clean.n_samples // 8)
    assert coherence[0] == pytest.approx(float(puu @ c / puu.sum()), rel=1e-6)


def test_an_output_that_does_not_respond_is_left_out_of_the_fit(clean):
    """A temperature channel exported beside the accelerometers, pooled with them, moved the
    supine ride's 13.7 Hz mode to 15.0 Hz: it is left out as a duplicate is, and the record
    fitted is the clean one, sample for sample. When no output responds there is nothing to
    keep instead, and every output stays (the warning says the modes are not the structure's)."""
    t = clean.time
    temperature = 20 + t / t[-1] + 0.01 * np.random.default_rng(0).standard_normal(clean.n_samples)
    extra = _with(clean, response=np.column_stack([clean.response, temperature]), sensors=(*clean.sensors, "temp"))
    prep, ref = prepare(extra), prepare(clean)
    assert prep.dropped == ("temp",) and prep.recording.sensors == clean.sensors
    # to rounding: each mean is taken over a differently shaped array
    np.testing.assert_allclose(prep.recording.response, ref.recording.response, rtol=0, atol=1e-12)
    (w,) = [w for w in prep.warnings if w.code == "incoherent_output"]
    assert w.channels == ("temp",) and "left out of the fit" in w.message
    assert not [w for w in prep.warnings if w.code == "unit_mismatch"]  # its scale no longer matters
    noise = np.random.default_rng(2).standard_normal(clean.response.shape)
    assert prepare(_with(clean, response=noise)).dropped == ()


@pytest.mark.parametrize(
    ("channel", "factor", "exact"),
    [(1, 1 / 9.80665, True), (2, 1000.0, True), (0, 1000 / 9.80665, False), (3, 100.0, False)],
)
def test_an_output_in_other_units_is_measured_named_and_converted(clean, channel, factor, exact):
    """Chest in g, pelvis 1000x, head in mg, legs in Gal among m/s²: the quasi-static ratio is
    the unit factor (within 5 %) and the channel is converted: by the exact factor where one
    unit conversion is that near (the prepared record is then the clean one), by the measured
    ratio where two are (mg 101.97 and Gal 100), which leaves the channel within the ratio's
    scatter (2 %) of the clean one."""
    from armaxmodal.prepare.units import UNIT_MATCH, unit_conversion

    y = clean.response.copy()
    y[:, channel] *= factor
    rec = _with(clean, response=y)
    found = [w for w in check_quality(rec) if w.code == "unit_mismatch"]
    assert [w.channels for w in found] == [(clean.sensors[channel],)]
    assert found[0].value == pytest.approx(factor, rel=UNIT_MATCH)
    divisor = unit_conversion(found[0].value)[0]
    assert (divisor == pytest.approx(factor, rel=1e-12)) == exact
    prepared = prepare(rec)
    reference = prepare(clean).recording.response[:, channel]
    (unit,) = [w for w in prepared.warnings if w.code == "unit_mismatch"]
    assert "Divided by" in unit.message
    np.testing.assert_allclose(
        prepared.recording.response[:, channel], reference * factor / divisor, rtol=1e-9, atol=1e-12
    )
    gain = np.std(prepared.recording.response[:, channel]) / np.std(reference)
    assert gain == pytest.approx(1.0, abs=1e-9 if exact else 0.02)


@pytest.mark.parametrize("factor", [7.0, 0.2, 9.0])
def test_a_scale_that_matches_no_unit_is_named_and_left(clean, factor):
    """x7 and x0.2 are no unit; x9 is 8 % from g's 9.81, beyond the 5 % a match allows."""
    y = clean.response.copy()
    y[:, 2] *= factor
    rec = _with(clean, response=y)
    prepared = prepare(rec)
    found = [w for w in prepared.warnings if w.code == "unit_mismatch"]
    assert [w.channels for w in found] == [("pelvis",)] and found[0].value == pytest.approx(factor, rel=0.05)
    assert "Convert it and rerun" in found[0].message
    np.testing.assert_allclose(prepared.recording.response[:, 2], prepare(clean).recording.response[:, 2] * factor)


def test_a_record_without_a_quasi_static_band_is_not_tested_and_one_output_only_against_the_input(clean):
    """Outputs at unrelated scales (no quasi-static band they share) say nothing; a single
    output 102 times its input is compared with the input alone: mg or Gal, both named."""
    for gains in ([30.0, 45.0, 60.0, 3000.0], [1.0, 30.0, 45.0, 60.0]):  # one output near 1 is no majority
        force_like = _with(clean, response=clean.response * np.array(gains))
        assert not [w for w in check_quality(force_like) if w.code == "unit_mismatch"]
    single = clean.select(["head"])
    single = _with(single, response=single.response * 102.0, sensors=("head",))
    (w,) = [w for w in check_quality(single) if w.code == "unit_mismatch"]
    assert w.channels == ("base",) and "mg where the input is in m/s² (101.97)" in w.message and "(100)" in w.message


@pytest.mark.parametrize(("scale", "words"), [(1 / 9.80665, "g where the input is in m/s²"), (9.80665, "m/s² where")])
def test_every_output_in_other_units_than_the_input_is_named_on_the_input(clean, scale, words):
    """Outputs in g with the base in m/s² (or the base in g): every output reads the same
    flat multiple of the input; named on the input, nothing converted (modes do not depend
    on it); a force input, whose |T| grows as f^2 (the F-16: 1.2-4x over the same lines), never."""
    rec = _with(clean, response=clean.response * scale)
    found = [w for w in check_quality(rec) if w.code == "unit_mismatch"]
    assert [w.channels for w in found] == [("base",)] and words in found[0].message
    assert found[0].value == pytest.approx(scale, rel=0.03)
    np.testing.assert_allclose(prepare(rec).recording.response, prepare(clean).recording.response * scale, rtol=1e-12)
    f = np.fft.rfftfreq(clean.n_samples, 1 / clean.fs)
    force = np.fft.irfft(np.fft.rfft(clean.response, axis=0) * (f[:, None] / 2.0) ** 2 * scale, clean.n_samples, axis=0)
    assert not [w for w in check_quality(_with(clean, response=force)) if w.code == "unit_mismatch"]


def test_the_ratio_is_taken_against_the_other_outputs(clean):
    """A base sensor 15 % off in sensitivity (every output reads 1.15) with the chest in g:
    against the others the chest reads 1/9.81 and is converted exactly; against the input it
    would read 0.117 and match nothing."""
    y = clean.response * 1.15
    y[:, 1] /= 9.80665
    found = [w for w in check_quality(_with(clean, response=y)) if w.code == "unit_mismatch"]
    assert [w.channels for w in found] == [("chest",)]
    assert found[0].value == pytest.approx(1 / 9.80665, rel=0.02)


def test_the_head_in_mg_no_longer_loses_modes(clean):
    """Before the check, the head in mg dominated every shape comparison and two of the four
    modes were merged away with no warning; converted, the selection is the clean one's."""
    y = clean.response.copy()
    y[:, 0] *= 1000 / 9.80665
    found = select_modes(stabilisation_diagram(_with(clean, response=y), n_jobs=1), segments=0)
    truth = am.supine_human().modes()
    np.testing.assert_allclose(found.modes.freq_hz, truth.freq_hz, rtol=FREQ_RTOL)


def test_a_sensor_that_stopped_updating_is_named_with_its_run(clean):
    """52 equal samples on pelvis from 50 s (a dropout) are named with their start and
    length; the clean record and a coarsely quantised one (a step of 0.3 on a unit RMS: equal
    neighbours on 15 % of its samples) are not: the test weighs a run against the channel's
    own rate of repeats. (At a step of half the RMS, 2 bits, it takes runs of 13 for stuck.)"""
    assert not [w for w in check_quality(clean) if w.code == "stuck_samples"]
    y = clean.response.copy()
    y[3000:3052, 2] = y[2999, 2]
    (w,) = [w for w in check_quality(_with(clean, response=y)) if w.code == "stuck_samples"]
    assert w.channels == ("pelvis",) and "for 53 samples in a row from 49.983 s" in w.message and w.value == 53
    coarse = np.round(clean.response / 0.3) * 0.3
    assert np.mean(coarse[1:] == coarse[:-1]) > 0.1
    assert not [w for w in check_quality(_with(clean, response=coarse)) if w.code == "stuck_samples"]


def test_a_few_padded_samples_at_the_edges_are_not_a_dropout_but_a_long_dead_end_is(clean):
    """A channel shifted into alignment repeats its first value a few times: padding, not
    reported; the last 60 samples (1 s) frozen are a dead sensor: reported."""
    from armaxmodal.prepare.quality import STUCK_EDGE_MIN

    y = clean.response.copy()
    y[:3, 0] = y[3, 0]
    assert 3 < STUCK_EDGE_MIN
    assert not [w for w in check_quality(_with(clean, response=y)) if w.code == "stuck_samples"]
    y = y.copy()  # the recording froze the first copy
    y[-60:, 1] = y[-61, 1]
    (w,) = [w for w in check_quality(_with(clean, response=y)) if w.code == "stuck_samples"]
    assert w.channels == ("chest",) and "for 61 samples" in w.message


def test_a_record_sampled_far_above_its_structure_says_so_and_its_advice_finds_the_modes():
    """The supine model at 1 kHz under a 0.5-400 Hz ride: the input excites far above the
    structure, so the rate is kept, and the sweep found one of the four modes with nothing
    said. Every mode found lies below 10 % of the Nyquist frequency: 'oversampled' names it
    and the band to use; with that band all four modes are found, within 1.5 %."""
    from armaxmodal.modes.settings import DEFAULTS
    from armaxmodal.prepare.resample import oversampling_note

    system = am.supine_human()
    ride = am.random_vibration(1000.0, 15.0, (0.5, 400.0), seed=1)
    rec = am.simulate_recording(system, ride, 1000.0, noise=0.05, seed=2, hold="bandlimited")
    first = select_modes(stabilisation_diagram(rec), segments=0)
    (w,) = [w for w in first.warnings if w.code == "oversampled"]
    top = first.modes.freq_hz.max()
    exact = system.modes().freq_hz
    # at this rate the sweep alone gave one of the four modes, then five (a split of 8.3 Hz);
    # the modal model counted by nested tests now finds the four (the note still says the rate
    # wastes the sweep's orders and time)
    assert len(first.modes) == 4 and np.allclose(first.modes.freq_hz, exact, rtol=0.015)
    assert w.value == pytest.approx(top / 500.0)
    hi = float(np.ceil(2.5 * top))
    assert f"rerun with --band 0:{hi:g}, which resamples to {1000 / (400 // hi):.4g} Hz" in w.message
    second = select_modes(stabilisation_diagram(rec, range(2, 25, 2), band=(0.0, hi)), segments=0)
    assert len(second.modes) == 4 and not [w for w in second.warnings if w.code == "oversampled"]
    np.testing.assert_allclose(second.modes.freq_hz, exact, rtol=0.015)
    # identify says it too (there it found 5.76, 8.48, 16.33 Hz, intervals far narrower than
    # its errors, fits of -66 % to 47 %, and no warning)
    with warnings.catch_warnings():  # whether PEM converges at this rate is not the point here
        warnings.simplefilter("ignore", am.ConvergenceWarning)
        ident = am.identify(rec, (8, 9, 8, -1))
    assert [w["code"] for w in ident.to_dict()["warnings"]].count("oversampled") == 1
    # the threshold: the highest mode at 10 % of the Nyquist frequency is not oversampled
    limits = DEFAULTS.notes.oversampled_fraction, DEFAULTS.notes.suggested_band_factor
    assert oversampling_note(np.array([3.0, 50.0]), 1000.0, *limits) == []
    assert oversampling_note(np.array([]), 1000.0, *limits) == []
    assert oversampling_note(np.array([49.9]), 1000.0, *limits)[0].value == pytest.approx(0.0998)


def test_a_lightly_damped_sensor_is_a_response_though_the_input_drives_it_little_elsewhere():
    """A 1 %-damped four-mass chain at 400 Hz (a count battery's body, rounded): its first two
    sensors move at the 13.4 and 20.0 Hz resonances and barely elsewhere, so over the input's
    0.5-180 Hz their noise floor dominates and their coherence averaged over the input's spectrum
    is below INCOHERENT. Most of their own power is coherent: they respond, and are kept (leaving
    them out lost the 27.97 Hz mode)."""
    from armaxmodal.prepare.quality import INCOHERENT, input_coherence

    s = am.Structure.from_chain([4.818, 8.406, 8.038, 2.565], [22235.9, 54564.2, 92832.2, 42092.7],
                                [2.721, 6.677, 11.360, 5.151], [73064.8, 28573.6, 58065.6], [8.941, 3.497, 7.105],
                                ("s0", "s1", "s2", "s3"))  # fmt: skip
    rec = am.simulate_recording(s, am.random_vibration(400.0, 120.0, (0.5, 180.0), seed=4), 400.0, noise=0.03,
                                seed=5)  # fmt: skip
    assert input_coherence(rec.base, rec.response, rec.fs)[:2].max() < INCOHERENT
    assert [w for w in check_quality(rec) if w.code == "incoherent_output"] == []


def test_a_response_sensor_with_a_strong_hum_beyond_the_input_band_still_responds(clean):
    """The other half of the rule: most of the head sensor's power made a 27 Hz hum, beyond the
    ride's 0.5-24 Hz, where the input has no power. Over its own spectrum little is coherent; over
    the input's the head still responds as before, so it is kept (the hum is for the disturbance
    checks, not a reason to drop the sensor)."""
    from armaxmodal.prepare.quality import INCOHERENT, input_coherence

    y = clean.response.copy()
    y[:, 0] += 5 * y[:, 0].std() * np.sin(2 * np.pi * 27.0 * clean.time)
    hummed = _with(clean, response=y)
    assert input_coherence(hummed.base, hummed.response, hummed.fs)[0] > 0.75 > INCOHERENT
    assert [w for w in check_quality(hummed) if w.code == "incoherent_output"] == []
