"""A mode's 95 % interval from its parts (armaxmodal.modes.intervals): each part's hull, worked out by hand.
A damping ratio's parts are taken on its logarithm: 0.05 with deviation 0.004 gives
0.05 exp(-+ 1.96 * 0.004 / 0.05)."""

import numpy as np
import pandas as pd
import pytest

from armaxmodal.modes.intervals import with_intervals
from armaxmodal.stats import Z95


def _row(**parts) -> pd.DataFrame:
    """One mode at 10 Hz, damping 0.05, standard deviations 0.1 Hz and 0.004, and ``parts``."""
    return pd.DataFrame([{"freq_hz": 10.0, "damping": 0.05, "freq_sd": 0.1, "damping_sd": 0.004, **parts}])


def _log(value: float, half: float) -> tuple[float, float]:
    """A damping interval by hand: ``value * exp(-+ half / value)``."""
    return value * np.exp(-half / value), value * np.exp(half / value)


def _ci(out: pd.DataFrame, q: str) -> tuple[float, float]:
    return float(out[f"{q}_ci95_lo"].iloc[0]), float(out[f"{q}_ci95_hi"].iloc[0])


def test_the_estimate_alone_gives_its_own_interval():
    out = with_intervals(_row())
    assert _ci(out, "freq") == pytest.approx((10 - Z95 * 0.1, 10 + Z95 * 0.1), rel=1e-12)
    assert _ci(out, "damping") == pytest.approx(_log(0.05, Z95 * 0.004), rel=1e-12)


def test_a_damping_interval_never_reaches_zero_and_stops_at_critical_damping():
    """A deviation larger than the damping itself (the symmetric interval [-0.063, 0.083] of a
    light mode): the interval stays positive, spans more than a factor e either side, and its
    upper end stops at 1."""
    out = with_intervals(_row(damping=0.01, damping_sd=0.0373))
    lo, hi = _ci(out, "damping")
    assert lo == pytest.approx(0.01 * np.exp(-Z95 * 3.73), rel=1e-12) and 0 < lo < 0.01 / np.e
    assert hi == 1.0
    small = with_intervals(_row(damping=0.02, damping_sd=1e-5))  # a small deviation: the symmetric interval
    assert _ci(small, "damping") == pytest.approx((0.02 - Z95 * 1e-5, 0.02 + Z95 * 1e-5), rel=1e-6)


def test_another_structure_widens_only_the_side_it_reaches():
    # the other count's interval reaches lower (9.5) but not higher (10.1 is inside the own 10.196)
    out = with_intervals(_row(freq_other_lo=9.5, freq_other_hi=10.1, damping_other_lo=np.nan,
                              damping_other_hi=0.07))  # fmt: skip
    assert _ci(out, "freq") == pytest.approx((9.5, 10 + Z95 * 0.1), rel=1e-12)
    assert _ci(out, "damping") == pytest.approx((_log(0.05, Z95 * 0.004)[0], 0.07), rel=1e-12)


def test_the_segments_widen_where_their_spread_dominates():
    out = with_intervals(_row(freq_segment_half=0.5, damping_segment_half=np.nan))
    assert _ci(out, "freq") == pytest.approx((9.5, 10.5), rel=1e-12)
    assert _ci(out, "damping") == pytest.approx(_log(0.05, Z95 * 0.004), rel=1e-12)
    damped = with_intervals(_row(damping_segment_half=0.02))  # wider than the statistical 0.0078: on the logarithm
    assert _ci(damped, "damping") == pytest.approx(_log(0.05, 0.02), rel=1e-12)
    narrow = with_intervals(_row(freq_segment_half=0.01))  # within the statistical interval: no change
    assert _ci(narrow, "freq") == pytest.approx((10 - Z95 * 0.1, 10 + Z95 * 0.1), rel=1e-12)


def test_the_hull_of_all_parts_then_the_scale_about_the_value():
    out = with_intervals(_row(freq_other_lo=9.0, freq_other_hi=10.2, freq_segment_half=0.6), scale=2.0)
    assert _ci(out, "freq") == pytest.approx((10 - 2 * 1.0, 10 + 2 * 0.6), rel=1e-12)
    assert _ci(out, "damping") == pytest.approx(_log(0.05, 2 * Z95 * 0.004), rel=1e-12)  # the scale on the logarithm


def test_no_deviation_no_interval_from_other_structures():
    """An estimate without a standard deviation has no interval: another model's is not its own."""
    out = with_intervals(_row(freq_sd=np.nan, freq_other_lo=9.0, freq_other_hi=11.0))
    assert np.isnan(_ci(out, "freq")).all()


def test_the_parts_are_kept_and_the_input_is_not_changed():
    row = _row(freq_other_lo=9.0)
    out = with_intervals(row)
    assert "freq_ci95_lo" not in row and out.freq_other_lo.iloc[0] == 9.0 and out.freq_sd.iloc[0] == 0.1


def test_a_selection_reports_its_parts_and_widens_for_filled_samples():
    """The same record selected twice, once said to hold 720 filled samples of 7,200: the same
    values and parts, every reported interval wider about its value by sqrt(7200 / 6480)."""
    from dataclasses import replace

    import armaxmodal as am

    ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 120.0, seed=1), 60.0, noise=0.03,
                                 seed=2)  # fmt: skip
    diagram = am.stabilisation_diagram(ride, range(4, 13, 2))
    whole = am.select_modes(diagram, segments=0)
    filled = am.QualityWarning("gap_filled", ("head",), "720 samples filled", 720.0)
    gapped = replace(diagram, recording=ride.with_meta({**ride.meta, "read_warnings": [filled]}))
    widened = am.select_modes(gapped, segments=0)
    k = np.sqrt(7200 / 6480)
    assert "gap_filled" in [w.code for w in widened.warnings]
    a, b = whole.modes, widened.modes
    np.testing.assert_allclose(a.freq_hz, b.freq_hz, rtol=1e-9)  # the same fits, to rounding
    np.testing.assert_allclose(a.freq_sd, b.freq_sd, rtol=1e-6)
    for side in ("lo", "hi"):
        col = f"freq_ci95_{side}"
        np.testing.assert_allclose(b[col] - b.freq_hz, k * (a[col] - a.freq_hz), rtol=1e-6)
        col = f"damping_ci95_{side}"  # the damping's on its logarithm
        np.testing.assert_allclose(np.log(b[col] / b.damping), k * np.log(a[col] / a.damping), rtol=1e-6)
    own = with_intervals(a.drop(columns=[c for c in a if "other" in c or "segment_half" in c]))
    assert np.all(a.freq_ci95_lo <= own.freq_ci95_lo) and np.all(a.freq_ci95_hi >= own.freq_ci95_hi)


def test_a_damping_that_is_not_positive_has_no_interval_on_the_logarithm():
    """A pole with zero or negative damping (a line, an unstable pole) has no log-scale interval:
    NaN, not a mirrored or infinite one."""
    from armaxmodal.stats import damping_interval

    lo, hi = damping_interval(np.array([-0.01, 0.0, 0.02]), np.array([0.001, 0.001, Z95 * 0.001]))
    assert np.isnan(lo[:2]).all() and np.isnan(hi[:2]).all()
    assert (lo[2], hi[2]) == pytest.approx(_log(0.02, Z95 * 0.001), rel=1e-12)


def test_neighbours_not_separated_are_taken_left_to_right_without_overlap():
    """Each pair's gap in standard deviations of its difference (each from the pair's own
    intervals); after a pair the next test starts at the mode after it."""
    from armaxmodal.modes.intervals import not_separated

    def modes(f, sd):
        return with_intervals(pd.DataFrame({"freq_hz": f, "freq_sd": sd, "damping": 0.05, "damping_sd": 0.001}))

    # 10.0/10.1 and 20.0/20.5 are pairs (0.35 and 0.50 SD apart); 20.5/20.9 are 5.7 apart
    got = not_separated(modes([10.0, 10.1, 20.0, 20.5, 20.9], [0.2, 0.2, 1.0, 0.05, 0.05]))
    assert [(i, j) for i, j, _ in got] == [(0, 1), (2, 3)]
    np.testing.assert_allclose([gap for _, _, gap in got], [0.1 / np.hypot(0.2, 0.2), 0.5 / np.hypot(1.0, 0.05)])
    # 20.0/20.5 with SDs of 0.05 each are 7.1 apart, whatever the wider modes before them
    got = not_separated(modes([10.0, 10.1, 20.0, 20.5], [0.2, 0.2, 0.05, 0.05]))
    assert [(i, j) for i, j, _ in got] == [(0, 1)]


def test_the_two_estimators_test_by_hand():
    """Three modes, the third without an earlier estimate (a pick): 4 Hz's frequency and 9 Hz's
    damping each differ by 7.07 standard deviations of the difference, a sum of squares of 100 for
    4 values against the 99 % point 13.3. Both modes' intervals widen, each for its own quantity,
    and the note says where; differences within the noise change nothing."""
    from armaxmodal.modes.intervals import covering_both_estimators

    rows = pd.DataFrame({"freq_hz": [4.0, 9.0, 16.0], "freq_sd": [0.01, 0.01, 0.01], "damping": [0.05, 0.03, 0.02],
                         "damping_sd": [0.002, 0.001, 0.001], "freq_earlier": [4.1, 9.0, np.nan],
                         "freq_earlier_sd": [0.01, 0.01, np.nan], "damping_earlier": [0.05, 0.04, np.nan],
                         "damping_earlier_sd": [0.002, 0.001, np.nan]})  # fmt: skip
    out, (note,) = covering_both_estimators(rows, alpha=0.01)
    assert out.estimator_widened.tolist() == [True, True, False]
    np.testing.assert_allclose(out.freq_estimator_hi[:2], [4.1 + Z95 * 0.01, 9.0 + Z95 * 0.01])
    assert np.isnan(out.freq_estimator_lo[2]) and np.isnan(out.damping_estimator_hi[2])
    assert (note.code, note.channels) == ("estimators_disagree", ()) and note.value == pytest.approx(100.0)
    assert note.message == (
        "the modal model's modes and the diagram's fit of them differ beyond their noise (sum of squared standardised "
        "differences 100.0 for 4 values, its 99 % point 13.3): one of them is biased here, by model error the two "
        "weight differently (a nonlinearity, the inter-sample behaviour, leakage) or by orders too low for a mode. "
        "One record cannot say which, so every mode's interval covers both estimates; widened at 4.000, 9.000 Hz"
    )
    near = rows.assign(freq_earlier=[4.01, 9.0, np.nan], damping_earlier=[0.05, 0.031, np.nan])
    out, notes = covering_both_estimators(near, alpha=0.01)
    assert notes == [] and out.estimator_widened.tolist() == [False, False, False]
    assert out[["freq_estimator_lo", "damping_estimator_hi"]].isna().all().all()
    # rows with no earlier estimate at all (the selection's own) are not tested
    out, notes = covering_both_estimators(rows[["freq_hz", "freq_sd", "damping", "damping_sd"]])
    assert notes == [] and out.freq_earlier.isna().all() and out.estimator_widened.dtype == bool


def test_the_earlier_estimate_of_a_row():
    """A selection row's values as the earlier estimate, NaN deviations where it has none; a row of
    the modal model itself has no earlier estimate."""
    from armaxmodal.modes.intervals import earlier_estimate

    got = earlier_estimate({"freq_hz": 5.0, "damping": 0.1, "freq_sd": 0.02, "estimator": "armax"})
    assert (got["freq_earlier"], got["freq_earlier_sd"], got["damping_earlier"]) == (5.0, 0.02, 0.1)
    assert np.isnan(got["damping_earlier_sd"])
    assert all(np.isnan(v) for v in earlier_estimate({"freq_hz": 5.0, "damping": 0.1, "estimator": "ml-zoh"}).values())
