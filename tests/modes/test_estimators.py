"""Two estimators that disagree (armaxmodal.modes.intervals): Hausman's statistic worked out by hand,
its level, and the intervals that then cover both estimates."""

import numpy as np
import pandas as pd
import pytest
import scipy.stats

from armaxmodal.modes.intervals import covering_both_estimators, earlier_estimate, with_intervals
from armaxmodal.stats import Z95


def _rows(shift_sd: float, n: int = 3) -> pd.DataFrame:
    """``n`` modes whose modal-model frequencies lie ``shift_sd`` standard deviations of the
    difference above the earlier estimate (SDs 0.03 and 0.04 Hz: the difference's is 0.05) and
    whose damping ratios agree."""
    f = 5.0 * np.arange(1, n + 1)
    return pd.DataFrame({
        "freq_hz": f + 0.05 * shift_sd, "freq_sd": 0.03, "freq_earlier": f, "freq_earlier_sd": 0.04,
        "damping": 0.02, "damping_sd": 0.001, "damping_earlier": 0.02, "damping_earlier_sd": 0.002,
    })  # fmt: skip


def _shift_for(p: float, n: int = 3) -> float:
    """The common shift (in SDs) whose statistic ``n z^2`` sits at the chi-squared(2n) point of ``p``."""
    return float(np.sqrt(scipy.stats.chi2.isf(p, 2 * n) / n))


def test_the_statistic_is_the_sum_of_squared_standardised_differences():
    out, notes = covering_both_estimators(_rows(3.0))  # 3 frequencies at z = 3: 27 for 6 values
    assert [n.code for n in notes] == ["estimators_disagree"]
    assert notes[0].value == pytest.approx(27.0, rel=1e-9)
    assert "27.0 for 6 values" in notes[0].message and "16.8" in notes[0].message  # chi2(6)'s 1 % point


def test_the_test_is_at_one_percent():
    """Between the 1 % and 0.1 % points the intervals widen; between 5 % and 1 % they do not."""
    widened, notes = covering_both_estimators(_rows(_shift_for(0.005)))
    assert notes and widened.estimator_widened.all()
    kept, none = covering_both_estimators(_rows(_shift_for(0.02)))
    assert not none and not kept.estimator_widened.any()
    assert kept[["freq_estimator_lo", "freq_estimator_hi", "damping_estimator_lo"]].isna().all().all()


def test_where_they_disagree_every_interval_covers_the_earlier_one():
    out, _ = covering_both_estimators(_rows(3.0))
    np.testing.assert_allclose(out.freq_estimator_lo, out.freq_earlier - Z95 * 0.04, rtol=1e-12)
    np.testing.assert_allclose(out.freq_estimator_hi, out.freq_earlier + Z95 * 0.04, rtol=1e-12)
    ci = with_intervals(out)
    # the earlier interval reaches lower than the own (f + 0.15 - 1.96 * 0.03): it sets the low end
    np.testing.assert_allclose(ci.freq_ci95_lo, out.freq_earlier - Z95 * 0.04, rtol=1e-12)
    np.testing.assert_allclose(ci.freq_ci95_hi, out.freq_hz + Z95 * 0.03, rtol=1e-12)
    # the damping agrees, but its earlier interval is the wider: it is covered too (on the logarithm)
    np.testing.assert_allclose(ci.damping_ci95_lo, 0.02 * np.exp(-Z95 * 0.002 / 0.02), rtol=1e-12)
    np.testing.assert_allclose(out.damping_estimator_hi, 0.02 * np.exp(Z95 * 0.002 / 0.02), rtol=1e-12)
    assert out.estimator_widened.all()


def test_a_mode_whose_earlier_interval_lies_within_its_own_is_not_said_widened():
    rows = _rows(4.0)
    rows.loc[0, ["freq_earlier", "freq_earlier_sd", "damping_earlier_sd"]] = [rows.freq_hz[0], 0.01, 0.0005]
    out, notes = covering_both_estimators(rows)
    assert notes and list(out.estimator_widened) == [False, True, True]
    ci = with_intervals(out)
    assert ci.freq_ci95_lo[0] == pytest.approx(rows.freq_hz[0] - Z95 * 0.03, rel=1e-12)


def test_a_mode_without_an_earlier_estimate_is_neither_tested_nor_widened():
    rows = _rows(3.0)
    rows.loc[1, ["freq_earlier", "freq_earlier_sd", "damping_earlier", "damping_earlier_sd"]] = np.nan
    out, notes = covering_both_estimators(rows)
    assert notes[0].value == pytest.approx(18.0, rel=1e-9) and "for 4 values" in notes[0].message
    assert list(out.estimator_widened) == [True, False, True]
    assert np.isnan(out.freq_estimator_lo[1])
    alone, none = covering_both_estimators(rows.drop(columns=["freq_earlier", "freq_earlier_sd", "damping_earlier",
                                                              "damping_earlier_sd"]))  # fmt: skip
    assert not none and not alone.estimator_widened.any()


def test_the_earlier_estimate_is_the_diagrams_not_the_modal_models():
    row = {"freq_hz": 7.3, "freq_sd": 0.01, "damping": 0.005, "damping_sd": 0.0002, "estimator": "armax"}
    assert earlier_estimate(row) == {"freq_earlier": 7.3, "freq_earlier_sd": 0.01, "damping_earlier": 0.005,
                                     "damping_earlier_sd": 0.0002}  # fmt: skip
    assert np.isnan(list(earlier_estimate({**row, "estimator": "ml-zoh"}).values())).all()


@pytest.mark.parametrize("ratio", [0.0, 0.3])
def test_a_cubic_spring_makes_the_estimators_disagree_and_its_linear_twin_does_not(ratio):
    """The supine human with a cubic spring between chest and pelvis (its force 0.3 of the linear
    spring's at the RMS deflection) and without it: only the nonlinear ride's modal model and ARMAX
    fit disagree beyond their noise (statistic 20 for the three modes both estimate; the fourth, near
    13.8 Hz, is the count's split, which the ARMAX fits merge), and there every reported interval
    holds the ARMAX value its mode was counted from."""
    import armaxmodal as am
    from armaxmodal.diagnosis.inject import cubic_spring_ride

    ride = cubic_spring_ride(am.supine_human(), am.random_vibration(60.0, 120.0, seed=1), 60.0, (1, 2), ratio, seed=2)
    selection = am.select_modes(am.stabilisation_diagram(ride, range(4, 13, 2)))
    notes = [w for w in selection.warnings if w.code == "estimators_disagree"]
    m = selection.modes
    if ratio == 0.0:
        assert not notes and not m.estimator_widened.any()
        return
    both = m[np.isfinite(m.freq_earlier.to_numpy(float))]  # the modes both estimators give
    assert len(both) >= 3 and len(notes) == 1 and notes[0].value > scipy.stats.chi2.isf(0.01, 2 * len(both))
    assert both.estimator_widened.any()
    assert ((both.freq_ci95_lo <= both.freq_earlier) & (both.freq_earlier <= both.freq_ci95_hi)).all()
    assert ((both.damping_ci95_lo <= both.damping_earlier) & (both.damping_earlier <= both.damping_ci95_hi)).all()
    flags = [r["interval_covers_other_estimator"] for r in selection.to_dict()["modes"]]
    assert flags == m.estimator_widened.tolist()  # the JSON says which intervals were widened to cover it
