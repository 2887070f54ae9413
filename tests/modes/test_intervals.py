"""A mode's 95 % interval from its parts (armaxmodal.modes.intervals): each part's hull, worked out by hand."""

import numpy as np
import pandas as pd
import pytest

from armaxmodal.modes.intervals import with_intervals
from armaxmodal.stats import Z95


def _row(**parts) -> pd.DataFrame:
    """One mode at 10 Hz, damping 0.05, standard deviations 0.1 Hz and 0.004, and ``parts``."""
    return pd.DataFrame([{"freq_hz": 10.0, "damping": 0.05, "freq_sd": 0.1, "damping_sd": 0.004, **parts}])


def _ci(out: pd.DataFrame, q: str) -> tuple[float, float]:
    return float(out[f"{q}_ci95_lo"].iloc[0]), float(out[f"{q}_ci95_hi"].iloc[0])


def test_the_estimate_alone_gives_its_own_interval():
    out = with_intervals(_row())
    assert _ci(out, "freq") == pytest.approx((10 - Z95 * 0.1, 10 + Z95 * 0.1), rel=1e-12)
    assert _ci(out, "damping") == pytest.approx((0.05 - Z95 * 0.004, 0.05 + Z95 * 0.004), rel=1e-12)


def test_another_structure_widens_only_the_side_it_reaches():
    # the other count's interval reaches lower (9.5) but not higher (10.1 is inside the own 10.196)
    out = with_intervals(_row(freq_other_lo=9.5, freq_other_hi=10.1, damping_other_lo=np.nan,
                              damping_other_hi=0.07))  # fmt: skip
    assert _ci(out, "freq") == pytest.approx((9.5, 10 + Z95 * 0.1), rel=1e-12)
    assert _ci(out, "damping") == pytest.approx((0.05 - Z95 * 0.004, 0.07), rel=1e-12)


def test_the_segments_widen_where_their_spread_dominates():
    out = with_intervals(_row(freq_segment_half=0.5, damping_segment_half=np.nan))
    assert _ci(out, "freq") == pytest.approx((9.5, 10.5), rel=1e-12)
    assert _ci(out, "damping") == pytest.approx((0.05 - Z95 * 0.004, 0.05 + Z95 * 0.004), rel=1e-12)
    narrow = with_intervals(_row(freq_segment_half=0.01))  # within the statistical interval: no change
    assert _ci(narrow, "freq") == pytest.approx((10 - Z95 * 0.1, 10 + Z95 * 0.1), rel=1e-12)


def test_the_hull_of_all_parts_then_the_scale_about_the_value():
    out = with_intervals(_row(freq_other_lo=9.0, freq_other_hi=10.2, freq_segment_half=0.6), scale=2.0)
    assert _ci(out, "freq") == pytest.approx((10 - 2 * 1.0, 10 + 2 * 0.6), rel=1e-12)
    assert _ci(out, "damping") == pytest.approx((0.05 - 2 * Z95 * 0.004, 0.05 + 2 * Z95 * 0.004), rel=1e-12)


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
    for q, value in (("freq", "freq_hz"), ("damping", "damping")):
        for side in ("lo", "hi"):
            col = f"{q}_ci95_{side}"
            np.testing.assert_allclose(b[col] - b[value], k * (a[col] - a[value]), rtol=1e-6)
    own = with_intervals(a.drop(columns=[c for c in a if "other" in c or "segment_half" in c]))
    assert np.all(a.freq_ci95_lo <= own.freq_ci95_lo) and np.all(a.freq_ci95_hi >= own.freq_ci95_hi)
