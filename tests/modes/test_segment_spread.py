"""Segment spread against simulated truth: a time-invariant ride keeps its statistical
intervals; a ride whose stiffness changes half-way is flagged and its intervals widened."""

import numpy as np
import pytest

import armaxmodal as am
from armaxmodal.modes.diagram import stabilisation_diagram
from armaxmodal.modes.intervals import apply_segment_spread, with_intervals
from armaxmodal.modes.pipeline import select_modes
from armaxmodal.stats import Z95

FS = 60.0
# the stiffer half of the changing ride: every spring 12 % stiffer (modes about 6 % higher)
STIFFENING = 1.12


def _ride(structure, seed, duration=60.0):
    u = am.random_vibration(FS, duration, (0.5, 28.0), seed=seed)
    return am.simulate_recording(structure, u, FS, noise=0.05, hold="zoh", seed=seed + 100)


def test_a_time_invariant_ride_is_not_flagged(fixtures_dir):
    rec = am.read_recording(fixtures_dir / "supine_random_zoh.csv")
    selection = select_modes(stabilisation_diagram(rec, per_sensor=False))
    assert not selection.modes.model_error_dominates.any()
    assert (selection.modes.segments_found == 3).all()
    assert "model_error_dominates" not in {w.code for w in selection.warnings}


def test_a_stiffness_change_half_way_is_flagged_and_widened():
    s = am.supine_human()
    stiff = am.Structure(s.M, s.C, s.K * STIFFENING, s.names)
    first, second = _ride(s, 1), _ride(stiff, 2)
    rec = am.Recording(
        FS,
        np.concatenate([first.base, second.base]),
        np.vstack([first.response, second.response]),
        first.sensors,
    )
    selection = select_modes(stabilisation_diagram(rec, per_sensor=False), segments=3)
    modes = selection.modes
    assert modes.model_error_dominates.any()
    assert "model_error_dominates" in {w.code for w in selection.warnings}
    # the widened intervals of the first (best-determined) mode cover both halves' truths
    f1 = [s.modes().freq_hz[0], stiff.modes().freq_hz[0]]
    lo, hi = modes.freq_ci95_lo.iloc[0], modes.freq_ci95_hi.iloc[0]
    assert modes.model_error_dominates.iloc[0]
    assert lo <= min(f1) * 1.01 and hi >= max(f1) * 0.99, (lo, hi, f1)


def test_widening_follows_the_chi_square_rule():
    """Three segments: flagged when 2 s^2 / (3 sigma^2) exceeds the chi-square quantile."""
    import pandas as pd
    from scipy.stats import chi2, t

    sigma = 0.01
    base = {"freq_hz": 5.0, "damping": 0.2, "freq_sd": sigma, "freq_sd_armax": sigma, "damping_sd": 0.005,
            "damping_sd_armax": 0.005}  # fmt: skip
    crit = chi2.ppf(1 - 0.01 / 2, 2)
    s_edge = sigma * np.sqrt(3 * crit / 2)
    for s, flagged in ((0.98 * s_edge, False), (1.02 * s_edge, True)):
        spread = pd.DataFrame([{"freq_segment_sd": s, "damping_segment_sd": 0.0, "segments_found": 3}])
        out, notes = apply_segment_spread(pd.DataFrame([base]), spread)
        out = with_intervals(out)
        assert bool(out.model_error_dominates.iloc[0]) is flagged
        assert [w.code for w in notes] == (["model_error_dominates"] if flagged else [])
        half = (out.freq_ci95_hi.iloc[0] - out.freq_ci95_lo.iloc[0]) / 2
        want = max(t.ppf(0.975, 2) * s / np.sqrt(3), Z95 * sigma) if flagged else Z95 * sigma
        assert half == pytest.approx(want, rel=1e-9)


def test_a_segment_that_blends_a_close_pair_measures_neither_mode():
    """Two modes 3 % apart fitted at one order on three segments: the middle segment finds one
    pole between them. It is neither mode's, so each mode's spread is the two other segments', not
    the pair's gap; a pole nearer the other mode is never this one's."""
    import pandas as pd

    from armaxmodal.modes.intervals import segment_spread

    modes = pd.DataFrame({"freq_hz": [10.12, 10.41], "damping": [0.01, 0.01]})
    orders = (4, 5, 4, 0)

    def poles(*freqs):
        return pd.DataFrame({"freq_hz": freqs, "damping": [0.01] * len(freqs)})

    fitted = {(orders, 0): poles(10.11, 10.42), (orders, 1): poles(10.24), (orders, 2): poles(10.13, 10.40)}
    fitted[(orders, 2)].damping = [0.014, 0.008]
    table = segment_spread(None, modes, lambda i: orders, 3, fitted=fitted)
    assert table.segments_found.tolist() == [2, 2]
    assert table.freq_segment_sd.to_numpy() == pytest.approx([np.std([10.11, 10.13], ddof=1),
                                                              np.std([10.42, 10.40], ddof=1)], rel=1e-9)  # fmt: skip
    assert table.damping_segment_sd.to_numpy() == pytest.approx([np.std([0.01, 0.014], ddof=1),
                                                                 np.std([0.01, 0.008], ddof=1)], rel=1e-9)  # fmt: skip
    # one segment holds two poles, both nearer the first mode: the second's is not taken
    crowded = {(orders, k): poles(10.10, 10.14, 10.40) for k in range(3)}
    crowded[(orders, 1)] = poles(10.10, 10.20)
    table = segment_spread(None, modes, lambda i: orders, 3, fitted=crowded)
    assert table.segments_found.tolist() == [2, 2]
    # a segment whose fit failed (None), found no pole, or found one growing (negative damping) where a
    # mode is, gives neither mode of the pair a value
    growing = pd.DataFrame({"freq_hz": [10.12, 10.41], "damping": [-0.01, 0.01]})
    for failed in (None, poles(), growing):
        table = segment_spread(None, modes, lambda i: orders, 3, fitted={**fitted, (orders, 1): failed})
        assert table.segments_found.tolist() == [2, 2]


def test_the_spread_test_by_hand():
    """Three segments, three modes, the family-wise 1 % spread over both parameters of all three
    (the chi-square quantile at 0.01 / 6 is 12.79): a mode seen in two segments only is not judged;
    a frequency spread whose statistic, 2 s^2 / (3 sigma^2), is 10 stays (the rate split the wrong way,
    quantile 8.40, would flag it); a damping spread of 66.7 is flagged, widened to t(2) s / sqrt(3), and said.
    A frequency without a statistical interval (sigma 0) is not judged."""
    import pandas as pd

    modes = pd.DataFrame({"freq_hz": [4.0, 9.0, 16.0], "freq_sd_armax": [0.01, 0.01, 0.0],
                          "damping_sd_armax": [0.001, 0.001, 0.001]}, index=[10, 11, 12])  # fmt: skip
    spread = pd.DataFrame({"freq_segment_sd": [1.0, 0.01 * np.sqrt(15.0), 0.05],
                           "damping_segment_sd": [1.0, 0.0005, 0.01], "segments_found": [2, 3, 3]},
                          index=[3, 4, 5])  # fmt: skip
    out, (note,) = apply_segment_spread(modes, spread, 3, alpha=0.01)
    assert list(out.columns) == [*modes.columns, *spread.columns, "model_error_dominates", "freq_segment_half",
                                 "damping_segment_half"]  # fmt: skip
    assert out.model_error_dominates.tolist() == [False, False, True]
    assert np.isnan(out.freq_segment_half).all()
    np.testing.assert_allclose(out.damping_segment_half, [np.nan, np.nan, 4.302653 * 0.01 / np.sqrt(3)], rtol=1e-6)
    assert (note.code, note.channels, note.value) == ("model_error_dominates", (), 1.0)
    assert note.message == (
        "refitted on 3 disjoint segments, 1 mode(s) scatter beyond their statistical intervals: 16 Hz (segment SD "
        "0.05 Hz, damping 0.01). Their 95 % intervals were widened to the segments' spread. The model misses an "
        "effect of the data (amplitude-dependent or time-varying behaviour, a disturbance, a missing mode)."
    )


def test_the_segments_fitted_here_are_those_the_selection_schedules(fixtures_dir):
    """Without ``fitted``, ``segment_spread`` fits each representative order on each segment itself:
    the same table as from the segment poles the selection's scheduler fits (``segment_poles``)."""
    import pandas as pd

    from armaxmodal.estimate.orders import default_nb, default_nc
    from armaxmodal.modes.intervals import segment_jobs, segment_poles, segment_spread

    ride = am.read_recording(fixtures_dir / "supine_random.csv")
    modes = pd.DataFrame({"freq_hz": [5.83, 8.31, 13.5], "damping": [0.3, 0.2, 0.2]})
    orders = {8: (8, default_nb(8, -1), default_nc(8), -1), 10: (10, default_nb(10, -1), default_nc(10), -1)}
    orders_of = [orders[8], orders[10], orders[10]].__getitem__
    parts = ride.split(3)
    fitted = {job: segment_poles(parts, job) for job in segment_jobs(sorted(set(orders.values())), 3)}
    mine = segment_spread(ride, modes, orders_of, 3, n_jobs=2)
    pd.testing.assert_frame_equal(mine, segment_spread(None, modes, orders_of, 3, fitted=fitted))
    assert mine.segments_found.tolist()[:2] == [3, 3]  # the weakly driven 13.5 Hz mode is not in every third
