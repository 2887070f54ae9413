"""The stabilisation diagram's rules on small hand-made pole tables: classes between
consecutive orders, clustering across orders, merging of split modes, the order cap and the
delay-edge warning, and the refit's hand-over. Each expected value follows from the rule's
definition in :mod:`armaxmodal.modes.stabilisation`; no fit runs, so these also serve the mutation
run (mutmut) over that module."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

import armaxmodal as am
from armaxmodal.exceptions import OrderError
from armaxmodal.modes.clusters import _supported, cluster_poles, merge_duplicates
from armaxmodal.modes.diagram import SAMPLES_PER_PARAMETER, _check_top_order, _delay_warnings, deepest_delay
from armaxmodal.modes.intervals import with_intervals
from armaxmodal.modes.poles import Tolerances, stability_classes
from armaxmodal.modes.settings import ClusterSettings, CountSettings
from armaxmodal.modes.state import SelectionState, _apply_refinement
from armaxmodal.stats import Z95

SHAPE = np.array([1.0 + 0.2j, 0.5 - 0.1j, -0.3 + 0.05j])


def _poles(rows) -> pd.DataFrame:
    """rows: (source, na, freq_hz, damping, vector)."""
    return pd.DataFrame(
        [{"source": s, "na": na, "freq_hz": f, "damping": x, "vector": np.asarray(v)} for s, na, f, x, v in rows]
    )


def test_classes_follow_frequency_then_damping_then_shape():
    other_shape = np.array([0.2 + 0.0j, 1.0, 0.9])
    poles = _poles(
        [
            ("shared", 2, 5.00, 0.100, SHAPE),
            ("shared", 2, 12.0, 0.050, SHAPE),
            ("shared", 4, 5.04, 0.104, SHAPE * (2 - 1j)),  # f 0.8 %, xi 4 %, same shape: f+d+v
            ("shared", 4, 12.1, 0.050, other_shape),  # f 0.8 %, same xi, other shape: f+d
            ("shared", 6, 5.04, 0.120, SHAPE),  # xi 15 % off the order before: f
            ("shared", 6, 12.3, 0.050, other_shape),  # f 1.6 % off: new
        ]
    )
    assert stability_classes(poles, Tolerances()) == ["new", "new", "f+d+v", "f+d", "f", "new"]


def test_single_sensor_classes_compare_residue_magnitudes():
    poles = _poles(
        [
            ("head", 2, 5.0, 0.1, [1.0]),
            ("head", 4, 5.0, 0.1, [1.09j]),  # |r| within 10 %: same
            ("head", 6, 5.0, 0.1, [1.30]),  # 19 % larger than the order before: not
            ("chest", 2, 5.0, 0.1, [1.0]),  # another source starts its own chain
        ]
    )
    assert stability_classes(poles, Tolerances()) == ["new", "f+d+v", "f+d", "new"]


def test_clusters_take_one_pole_per_order_within_frequency_and_damping():
    rows = []
    for na in (2, 4, 6, 8):
        rows += [("shared", na, 5.0 * (1 + 0.004 * na), 0.10, SHAPE), ("shared", na, 9.0, 0.02, SHAPE)]
    rows += [("shared", 8, 5.1, 0.10, SHAPE)]  # a second pole near 5 Hz at na = 8: its own cluster
    rows += [("shared", 6, 9.05, 0.05, SHAPE)]  # damping 150 % off the 9 Hz cluster's
    poles = _poles(rows).assign(energy=1.0)
    clusters = cluster_poles(poles, [2, 4, 6, 8], 0.05, 0.5)
    sizes = sorted(len(c) for c in clusters)
    assert sizes == [1, 1, 4, 4]
    for c in clusters:
        assert poles.loc[c, "na"].is_unique
    # by frequency alone the odd-damping pole joins nothing new: the 9 Hz cluster has its na = 6 already
    assert sorted(len(c) for c in cluster_poles(poles, [2, 4, 6, 8], 0.05, None)) == [1, 1, 4, 4]
    c = ClusterSettings()
    assert _supported(3, 7, c) and not _supported(2, 4, c) and not _supported(3, 10, c)
    assert _supported(2, 4, ClusterSettings(min_orders=2))  # the orders a stable pole needs are a setting


def _modes(freqs, dampings, support):
    return pd.DataFrame(
        {"freq_hz": freqs, "damping": dampings, "support": support, "count": [10] * len(freqs), "energy": 1.0}
    )


def test_split_modes_merge_within_resolution_or_bandwidth_with_alike_shapes():
    other = np.array([1.0, -1.0, 0.3 + 0.0j])
    # 10.00 and 10.15 Hz at 2 % damping (half-power 0.4 Hz): alike shapes merge, unlike stay
    modes = _modes([10.0, 10.15], [0.02, 0.02], [1.0, 0.6])
    assert merge_duplicates(modes, [SHAPE, SHAPE * 1j], 0.8, 60.0) == [0]
    assert merge_duplicates(modes, [SHAPE, other], 0.8, 60.0) == [0, 1]
    # within 2 / T (T = 10 s: 0.2 Hz) nothing tells them apart, whatever the shapes
    assert merge_duplicates(modes, [SHAPE, other], 0.8, 10.0) == [0]
    # beyond the bandwidth they are two modes; the weaker survives when it is the first
    far = _modes([10.0, 10.6], [0.02, 0.02], [0.5, 1.0])
    assert merge_duplicates(far, [SHAPE, SHAPE], 0.8, 60.0) == [0, 1]
    assert merge_duplicates(_modes([10.0, 10.15], [0.02, 0.02], [0.5, 1.0]), [SHAPE, SHAPE], 0.8, 60.0) == [1]


def _recording(n: int) -> am.Recording:
    rng = np.random.default_rng(n)
    return am.Recording(60.0, rng.standard_normal(n), rng.standard_normal((n, 1)), ("a",))


def test_delay_edge_warning_only_at_the_most_non_causal_delay_the_record_supports():
    rec = _recording(2000)  # 100 samples a parameter's worth: na = 10 supports nk down to 31 - 100 = -69
    assert deepest_delay(rec, 10) == -69
    (w,) = _delay_warnings(-69, rec, 10)
    assert w.code == "nk_at_search_edge" and w.value == -69.0 and w.channels == ("base",)
    assert (
        _delay_warnings(-68, rec, 10) == [] and _delay_warnings(-9, rec, 10) == [] and _delay_warnings(0, rec, 10) == []
    )


@pytest.mark.parametrize("na", [10, 30])
def test_order_cap_is_twenty_samples_a_parameter(na):
    per_sensor = 3 * na + 10
    _check_top_order(na, _recording(per_sensor * SAMPLES_PER_PARAMETER), None)  # exactly enough
    short = _recording(per_sensor * SAMPLES_PER_PARAMETER - 1)
    with pytest.raises(OrderError, match=f"supports at most na = {na - 1} "):
        _check_top_order(na, short, None)


def test_refit_is_reported_unless_it_left_the_mode():
    from types import SimpleNamespace

    modes = _modes([5.0, 9.0], [0.10, 0.05], [1.0, 1.0]).assign(
        estimator="armax", damped_freq_hz=0.0, freq_sd=0.0, damping_sd=0.0,
    )  # fmt: skip
    shapes = np.ones((2, 2), complex)
    ref = SimpleNamespace(
        freq_hz=np.array([5.1, 9.9]),  # mode 2 moved 10 %: beyond 5 %
        damping=np.array([0.12, 0.05]),
        freq_sd=np.array([0.01, 0.02]),
        damping_sd=np.array([0.002, 0.001]),
        shapes=np.full((2, 2), 2.0 + 1j),
    )
    out, out_shapes = _apply_refinement(modes, shapes, ref, 0.05, 0.5)
    out = with_intervals(out)
    assert out.estimator.tolist() == ["fd-bandlimited", "armax (refit moved too far)"]
    assert out.at[0, "freq_hz"] == 5.1 and out.at[0, "damping"] == 0.12
    assert out.at[0, "damped_freq_hz"] == pytest.approx(5.1 * np.sqrt(1 - 0.12**2))
    assert (out.at[0, "freq_ci95_lo"], out.at[0, "freq_ci95_hi"]) == pytest.approx((5.1 - 0.0196, 5.1 + 0.0196))
    damping_ci = (out.at[0, "damping_ci95_lo"], out.at[0, "damping_ci95_hi"])
    assert damping_ci == pytest.approx((0.12 * np.exp(-0.00392 / 0.12), 0.12 * np.exp(0.00392 / 0.12)), rel=1e-6)
    assert out.at[1, "freq_hz"] == 9.0
    np.testing.assert_array_equal(out_shapes[:, 0], ref.shapes[:, 0])
    np.testing.assert_array_equal(out_shapes[:, 1], shapes[:, 1])
    assert modes.at[0, "freq_hz"] == 5.0  # the input table is not changed
    # damping moved by more than half: the ARMAX value stays
    ref.damping = np.array([0.16, 0.05])
    assert _apply_refinement(modes, shapes, ref, 0.05, 0.5)[0].estimator[0] == "armax (refit moved too far)"


def test_class_rules_at_their_edges():
    # an order's unmatched pole does not stop its later poles from being classed
    poles = _poles([("shared", 2, 5.0, 0.1, SHAPE), ("shared", 4, 9.0, 0.1, SHAPE), ("shared", 4, 5.0, 0.1, SHAPE)])
    assert stability_classes(poles, Tolerances()) == ["new", "new", "f+d+v"]
    # two sensors: the shape test is the MAC (0.5 here), not the first residue's magnitude
    poles = _poles([("shared", 2, 5.0, 0.1, [1.0, 0.0]), ("shared", 4, 5.0, 0.1, [1.0, 1.0])])
    assert stability_classes(poles, Tolerances()) == ["new", "f+d"]
    # one sensor: the magnitude ratio for residues of any size, within 5 x 0.02 = 10 %
    sizes = [1e-3, 1.05e-3, 1.1655e-3]
    poles = _poles([("head", na, 5.0, 0.1, [r]) for na, r in zip((2, 4, 6), sizes, strict=True)])
    assert stability_classes(poles, Tolerances()) == ["new", "f+d+v", "f+d"]  # +5 %, then +11 %


def _band_limited(fs: float = 100.0, n: int = 6000) -> am.Recording:
    """60 s at 100 Hz of an input band-limited to about 2-20 Hz (f_min 0.05 Hz, f_max 45 Hz)."""
    from scipy.signal import butter, sosfiltfilt

    rng = np.random.default_rng(0)
    u = sosfiltfilt(butter(6, [2.0, 20.0], "bandpass", fs=fs, output="sos"), rng.standard_normal(n))
    return am.Recording(fs, u, rng.standard_normal((n, 1)), ("a",))


def test_rejection_reasons_each_at_its_threshold():
    from armaxmodal.modes.poles import UNRESOLVED_DAMPING, rejection_reasons
    from armaxmodal.spectra import excited_band

    rec = _band_limited()
    lo, hi = excited_band(rec)
    assert 1.0 < lo < 2.5 and 18.0 < hi < 30.0
    rows = [  # freq, damping, damping_sd, energy, reason
        (8.0, -0.01, 0.001, 1.0, "negative damping"),
        (8.0, -0.001, 0.001, 1.0, UNRESOLVED_DAMPING),  # its 95 % interval reaches above zero
        (8.0, -0.001, 0.0004, 1.0, "negative damping"),  # 1.96 sd = 0.00078 does not
        (8.0, 0.0, 0.0, 1.0, "negative damping"),
        (8.0, 0.61, 0.01, 1.0, "over-damped"),
        (8.0, 0.6, 0.01, 1.0, ""),  # the ceiling itself is allowed
        (0.04, 0.01, 0.001, 1.0, "near 0 Hz"),  # 3 / 60 s = 0.05 Hz
        (45.5, 0.01, 0.001, 1.0, "near Nyquist"),  # 0.45 fs = 45 Hz
        (hi * 1.05 * 1.01, 0.05, 0.001, 1.0, "no input energy"),  # beyond hi (1 + damping)
        (hi * 1.05 * 0.99, 0.05, 0.001, 1.0, ""),  # within it
        (lo * 0.95 * 0.99, 0.05, 0.001, 1.0, "no input energy"),
        (lo * 0.95 * 1.01, 0.05, 0.001, 1.0, ""),
        (8.0, 0.05, 0.001, 0.009, "negligible residue"),  # under 1 % of the order's strongest
        (8.0, 0.05, 0.001, 0.011, ""),
    ]
    poles = pd.DataFrame(
        [
            {"source": "shared", "na": 10, "freq_hz": f, "damping": x, "damping_sd": sd, "energy": e}
            for f, x, sd, e, _ in rows
        ]
    )
    assert rejection_reasons(poles, Tolerances(), rec) == [r[4] for r in rows]
    # a pole table without standard errors: a non-positive damping is plainly negative
    bare = pd.DataFrame([{"source": "shared", "na": 2, "freq_hz": 8.0, "damping": -0.001, "energy": 1.0}])
    assert rejection_reasons(bare, Tolerances(), rec) == ["negative damping"]
    # a user's lower frequency limit replaces the 3 / T default; so does a ceiling on energy's ratio
    low = pd.DataFrame([{"source": "shared", "na": 2, "freq_hz": 0.5, "damping": 0.05, "energy": 1.0}])
    assert rejection_reasons(low, Tolerances(min_freq_hz=1.0), rec) == ["near 0 Hz"]
    assert rejection_reasons(low.assign(freq_hz=0.06), Tolerances(), rec) != ["near 0 Hz"]  # 0.06 > 3 / 60 s


def test_order_cap_message_names_the_record_the_cause_and_a_supported_range():
    from types import SimpleNamespace

    from armaxmodal.quality_warnings import QualityWarning

    # 1,040 samples: (1040 // 20 - 1 - 6 - 3) // 3 = 14
    with pytest.raises(OrderError, match=r"this record \(1040 samples at 60 Hz\) supports at most na = 14 "):
        _check_top_order(30, _recording(1040), None)
    with pytest.raises(OrderError, match=r"supports at most na = 2 .*e\.g\. --orders 2:2\.$"):
        _check_top_order(30, _recording(100), None)  # never below na = 2
    with pytest.raises(OrderError, match=r"supports at most na = 46 .*e\.g\. --orders 2:40\.$"):
        _check_top_order(60, _recording(3000), None)  # the suggestion stays a sweep of usual size
    prep = SimpleNamespace(
        analysis_fs=60.0,
        original_fs=240.0,
        band=None,
        warnings=[
            QualityWarning("offset_removed", ("a",), "means removed.", 0.1),
            QualityWarning("narrowband_input", ("base",), "input power sits in 2.9-3.1 Hz.", 3.0),
        ],
    )
    with pytest.raises(OrderError) as err:
        _check_top_order(30, _recording(1040), prep)
    assert str(err.value).startswith("input power sits in 2.9-3.1 Hz; check that the input excites the structure. ")
    assert "(1040 samples at 60 Hz, resampled from 240 Hz to the input's band)" in str(err.value)
    with pytest.raises(OrderError, match=r"resampled from 240 Hz to the band\)"):  # the user's band
        _check_top_order(30, _recording(1040), SimpleNamespace(**{**vars(prep), "band": (0.0, 24.0)}))


def test_delay_edge_warning_says_the_bound_and_what_to_do():
    (w,) = _delay_warnings(-9, _recording(100), 2)
    assert "nk = -9 (9 samples, 150 ms) sits at the most non-causal delay this record supports" in w.message
    assert "for orders up to na = 2 (20 samples a parameter)" in w.message
    assert w.message.endswith("look at the sensor_delay check and align the channels, or sweep lower orders.")


def test_finite_or_none_keeps_numbers_and_drops_nan_and_inf():
    from armaxmodal.io.write import finite_or_none

    assert finite_or_none(np.float64(2.5)) == 2.5 and type(finite_or_none(np.float64(2.5))) is float
    assert finite_or_none(float("nan")) is None and finite_or_none(np.inf) is None and finite_or_none(None) is None


def test_candidates_are_shared_poles_kept_or_unresolved_inside_the_band():
    from armaxmodal.modes.clusters import candidate_poles
    from armaxmodal.modes.poles import UNRESOLVED_DAMPING

    poles = pd.DataFrame(
        {
            "source": ["shared", "shared", "shared", "head", "shared", "shared"],
            "freq_hz": [2.0, 5.0, 8.0, 5.0, 5.0, 3.0],
            "rejected": ["", "", "", "", "over-damped", UNRESOLVED_DAMPING],
        }
    )
    assert candidate_poles(poles, None).index.tolist() == [0, 1, 2, 5]
    assert candidate_poles(poles, (2.0, 5.0)).index.tolist() == [0, 1, 5]  # band edges included
    assert candidate_poles(poles, (3.0, 8.0)).index.tolist() == [1, 2, 5]


def test_modes_rank_their_orders_by_bic_then_order():
    from armaxmodal.modes.clusters import _ranked

    poles = pd.DataFrame({"na": [4, 8, 6, 10]})
    assert _ranked(poles, {4: 10.0, 6: -5.0, 8: 3.0, 10: -5.0}) == [6, 10, 8, 4]
    assert _ranked(poles, {8: 1.0}) == [8, 4, 6, 10]  # orders without a BIC go last


def test_mode_row_reports_the_representative_and_the_cluster_medoid_and_spread():
    from armaxmodal.modes.clusters import mode_row

    sub = pd.DataFrame(
        {
            "na": [4, 6, 8, 10],
            "freq_hz": [5.00, 5.02, 5.20, 5.01],
            "damping": [0.050, 0.052, 0.080, 0.049],
            "damping_sd": [0.004, 0.004, 0.004, 0.004],
            "energy": [1.0, 3.0, 2.0, 5.0],
        }
    )
    rep = pd.Series(
        {"na": 6, "freq_hz": 5.021, "damping": 0.0521, "damped_freq_hz": 5.01, "freq_sd": 0.01, "damping_sd": 0.0035,
         "freq_ci95_lo": 5.0, "freq_ci95_hi": 5.04}
    )  # fmt: skip
    row = mode_row(rep, sub, 10)
    assert row["freq_hz"] == 5.021 and row["damping_sd"] == 0.0035 and row["na"] == 6
    assert "freq_ci95_lo" not in row  # the interval is kept as its parts, combined on output
    assert (row["count"], row["support"], row["energy"]) == (4, 0.4, 2.5)
    assert row["freq_spread"] == pytest.approx(np.std(sub.freq_hz, ddof=1))
    assert row["damping_spread"] == pytest.approx(np.std(sub.damping, ddof=1))
    # the medoid: the least summed distance |df| / mean f + |dx| / scale (worked out by hand
    # from that definition); with damping standard errors above the mean damping they set
    # the scale, below it the mean does
    wide = pd.DataFrame(
        {"na": [2, 4, 6, 8, 10], "freq_hz": [4.79, 4.94, 5.25, 4.73, 5.19],
         "damping": [0.047, 0.063, 0.03, 0.045, 0.033], "damping_sd": 0.066, "energy": 1.0}
    )  # fmt: skip
    assert mode_row(rep, wide, 10)["medoid_freq_hz"] == 4.79
    narrow = wide.assign(freq_hz=[5.11, 4.81, 4.94, 4.7, 4.86], damping=[0.047, 0.034, 0.055, 0.045, 0.059])
    assert mode_row(rep, narrow.assign(damping_sd=0.002), 10)["medoid_freq_hz"] == 4.7


def _notes_modes(**overrides):
    base = {"freq_hz": 4.0, "freq_ci95_lo": 3.99, "freq_ci95_hi": 4.01, "damping": 0.002,
            "damping_ci95_lo": 0.0005, "damping_ci95_hi": 0.0035, "orders_damping_unresolved": 0}  # fmt: skip
    base.update(overrides)
    return pd.DataFrame([base])


def test_unresolved_damping_notes_state_the_facts_and_the_reason():
    from armaxmodal.modes.notes import unresolved_damping_notes as _unresolved_damping_notes

    assert _unresolved_damping_notes(_notes_modes(), 10) == []  # a resolved damping (a factor 7): no note
    # a factor e^2 (7.39), where a symmetric interval of the same deviation reaches zero, or critical damping
    assert len(_unresolved_damping_notes(_notes_modes(damping_ci95_hi=0.0005 * 7.4), 10)) == 1
    assert _unresolved_damping_notes(_notes_modes(damping_ci95_hi=0.0005 * 7.38), 10) == []
    assert len(_unresolved_damping_notes(_notes_modes(damping=0.5, damping_ci95_lo=0.3, damping_ci95_hi=1.0), 10)) == 1
    (note,) = _unresolved_damping_notes(_notes_modes(damping_ci95_lo=0.0), 10)  # interval reaches zero
    assert note.code == "damping_unresolved" and note.value == 4.0 and note.channels == ()
    assert note.message == (
        "mode at 4.000 Hz ([3.99, 4.01] Hz): damping 0.002, 95 % interval [0, 0.0035]. the damping is below "
        "what this record resolves: a longer record, or more excitation here, narrows it"
    )
    (note,) = _unresolved_damping_notes(_notes_modes(orders_damping_unresolved=2, model_error_dominates=True), 10)
    assert note.message == (
        "mode at 4.000 Hz ([3.99, 4.01] Hz): damping 0.002, 95 % interval [0.0005, 0.0035]; its estimate is not "
        "positive at 2 of 10 orders. the interval is the spread of the record's thirds (model_error_dominates): "
        "the thirds disagree about this damping; run 'armaxmodal diagnose'"
    )
    (note,) = _unresolved_damping_notes(_notes_modes(damping_ci95_hi=0.05, structure_widened=True), 10)
    assert note.message.endswith("the interval covers the other models the record finds as good (another number of "
                                 "modes, two poles reported as one) or the other estimator's value, which disagree "
                                 "about this damping")  # fmt: skip
    (note,) = _unresolved_damping_notes(_notes_modes(damping_ci95_hi=0.05, estimator_widened=True), 10)
    assert note.message.endswith("or the other estimator's value, which disagree about this damping")
    two = pd.concat([_notes_modes(damping_ci95_lo=-0.001), _notes_modes(freq_hz=9.0, damping_ci95_lo=0.0)])
    assert [n.value for n in _unresolved_damping_notes(two, 10)] == [4.0, 9.0]
    after_a_resolved_one = pd.concat([_notes_modes(), _notes_modes(freq_hz=9.0, damping_ci95_lo=0.0)])
    assert [n.value for n in _unresolved_damping_notes(after_a_resolved_one, 10)] == [9.0]


def test_per_sensor_table_and_its_weighted_averages():
    """Table 3.2 and Eqs. 3.35-3.36 from hand-made single-sensor poles: per sensor and mode
    the median over orders of the strongest kept pole within 5 % (NaN where the sensor shows
    the mode at fewer than half the orders from the mode's own up), and the |M|-weighted means."""
    from types import SimpleNamespace

    from armaxmodal.modes.result import per_sensor_table

    def replace(ns, **kw):
        return SimpleNamespace(**{**vars(ns), **kw})

    rows = [  # source, na, freq, damping, energy, constant, rejected
        ("a", 2, 5.01, 0.050, 1.0, 0.5 + 0.1j, ""),
        ("a", 4, 5.02, 0.052, 1.0, 0.6 + 0.1j, ""),
        ("a", 4, 5.20, 0.300, 0.1, 9.0 + 0.0j, ""),  # weaker pole at the same order: not taken
        ("a", 6, 4.99, 0.049, 1.0, 0.7 + 0.1j, ""),
        ("a", 6, 9.10, 0.020, 1.0, 0.2 + 0.0j, ""),
        ("b", 4, 5.00, 0.050, 1.0, 0.4 + 0.0j, "over-damped"),  # rejected poles do not count
        ("b", 4, 9.00, 0.021, 1.0, 0.3 + 0.0j, ""),
        ("b", 6, 8.80, 0.023, 1.0, 0.3 + 0.1j, ""),
    ]
    poles = pd.DataFrame(
        [
            {"source": s, "na": na, "freq_hz": f, "damping": x, "damped_freq_hz": f * np.sqrt(1 - x**2),
             "energy": e, "vector": np.array([c]), "rejected": r}
            for s, na, f, x, e, c, r in rows
        ]
    )  # fmt: skip
    fits = {("a", 8): None} | {(s, na): None for s in ("a", "b") for na in (2, 4, 6)}
    diagram = SimpleNamespace(poles=poles, fits=fits, recording=SimpleNamespace(sensors=("a", "b")))
    modes = pd.DataFrame({"freq_hz": [5.0, 9.0], "na": [4, 4]})
    shapes = np.array([[1.0, 0.5j], [0.2, -1.5]])
    table, weighted = per_sensor_table(diagram, modes, shapes, 0.05)
    t = table.set_index(["sensor", "mode"])
    assert t.loc[("a", 1), "freq_hz"] == 5.01 and t.loc[("a", 1), "damping"] == 0.050  # medians of 3
    damped = [5.01 * np.sqrt(1 - 0.05**2), 5.02 * np.sqrt(1 - 0.052**2), 4.99 * np.sqrt(1 - 0.049**2)]
    assert t.loc[("a", 1), "damped_freq_hz"] == np.median(damped)
    assert t.loc[("a", 1), "own_modal_constant"] == 0.6 + 0.1j  # at the mode's own order
    assert np.isnan(t.loc[("b", 1), "freq_hz"])  # b keeps no pole near 5 Hz
    assert np.isnan(t.loc[("a", 2), "freq_hz"])  # near 9 Hz at one of a's orders 4, 6, 8: under half
    assert t.loc[("b", 2), "freq_hz"] == pytest.approx(8.9) and t.loc[("b", 2), "own_modal_constant"] == 0.3
    assert t.residue_mag.tolist() == [1.0, 0.2, 0.5, 1.5]  # mode by mode, sensor by sensor
    w = weighted.set_index("mode")
    assert w.loc[1, "freq_hz"] == 5.01 and w.loc[1, "sensors"] == 1
    assert w.loc[2, "freq_hz"] == pytest.approx(8.9) and w.loc[2, "damping"] == pytest.approx(0.022)
    # with a's 9.1 Hz pole at two orders it shows the mode too: the means weigh by |M|
    more = pd.concat([poles, poles.iloc[[4]].assign(na=8, freq_hz=9.12)], ignore_index=True)
    _, weighted = per_sensor_table(replace(diagram, poles=more), modes, shapes, 0.05)
    w = weighted.set_index("mode")
    assert w.loc[2, "sensors"] == 2
    assert w.loc[2, "freq_hz"] == pytest.approx((0.5 * 9.11 + 1.5 * 8.9) / 2.0)
    assert w.loc[2, "damping"] == pytest.approx((0.5 * 0.020 + 1.5 * 0.022) / 2.0)


def test_finished_pole_takes_the_nearest_finished_estimate_within_five_percent():
    from types import SimpleNamespace

    from armaxmodal.modes.clusters import _finished_pole

    def pole(freq_hz, damping, **extra):
        mu = np.exp((-damping + 1j) * 2 * np.pi * freq_hz / 100.0)
        return pd.Series({"na": 8, "freq_hz": freq_hz, "damping": damping, "pole": mu, **extra}, dtype=object)

    finished = pd.DataFrame([pole(5.1, 0.05), pole(9.0, 0.02), pole(20.0, 0.1)])
    diagram = SimpleNamespace()  # the cache holds order 8: nothing is fitted
    sweep = pole(5.0, 0.06, cls="f+d", rejected="")
    reach = ClusterSettings().freq  # 5 %
    out = _finished_pole(diagram, sweep, {8: finished}, reach)
    assert (out.freq_hz, out.damping, out.cls, out.rejected) == (5.1, 0.05, "f+d", "")
    assert _finished_pole(diagram, pole(9.4, 0.02), {8: finished}, reach).freq_hz == 9.0  # 4.3 % away: taken
    assert _finished_pole(diagram, pole(8.5, 0.02), {8: finished}, reach).freq_hz == 8.5  # 5.9 %: the sweep's stands
    assert _finished_pole(diagram, pole(9.4, 0.02), {8: finished}, 0.04).freq_hz == 9.4  # the reach is a setting
    assert _finished_pole(diagram, sweep, {8: finished.iloc[:0]}, reach).freq_hz == 5.0  # nothing finished


def test_refit_runs_inside_the_users_band_and_is_reported_only_for_band_limited_data():
    import armaxmodal.modes.state as st
    from armaxmodal.spectra import excited_band

    rec = _recording(2000)
    lo, hi = excited_band(rec)
    seen = []

    def refit(recording, freq_hz, damping, band_hz, hold, settings=None, decisive=None):
        seen.append(band_hz)
        # the hold is decided by the data, at the count's levels
        assert hold == "auto"
        assert decisive == CountSettings().decisive_bic
        return SimpleNamespace(hold="zoh")

    modes, shapes = _modes([5.0, 9.0], [0.1, 0.05], [1.0, 1.0]), np.eye(2, dtype=complex)
    assert st.refit_band(rec, (4.0, 12.0)) == (max(lo, 4.0), min(hi, 12.0))
    assert st.refit_band(rec, None) == (lo, hi)
    ref = st.selection_job(rec, [], modes, ("refit", (4.0, 12.0)), refine=refit)
    assert seen[-1] == (4.0, 12.0) and ref.hold == "zoh"
    work = SelectionState(modes, shapes)
    out = st.refined_modes(work, ref, 0.05, 0.5)
    # a held input: the ARMAX values are reported
    assert out.refinement is ref and out.modes is modes and out.shapes is shapes

    def failing(recording, freq_hz, damping, band_hz, hold, settings=None, decisive=None):
        raise OrderError("too few lines")

    failed = st.selection_job(rec, [], modes, ("refit", (lo, hi)), refine=failing)
    assert isinstance(failed, st.RefitFailure) and failed.reason == "too few lines"  # said, not silent
    (note,) = failed.notes()
    assert note.code == "refit_failed" and "too few lines" in note.message
    out = st.refined_modes(work, failed, 0.05, 0.5)
    assert out.refinement is None and out.modes is modes and out.shapes is shapes  # the ARMAX values stand


def _band_limited_refit(freq_hz, damping, shapes):
    freq_hz, damping = np.asarray(freq_hz, float), np.asarray(damping, float)
    return SimpleNamespace(hold="bandlimited", freq_hz=freq_hz, damping=damping, freq_sd=1e-3 * freq_hz,
                           damping_sd=1e-3 * damping, shapes=shapes)  # fmt: skip


@pytest.mark.parametrize(("freq_hz", "damping", "reported"), [
    ((5.2, 9.4), (0.11, 0.07), (True, True)),  # 4 % and 4.4 % in frequency, 10 % and 40 % in damping
    ((5.3, 9.0), (0.1, 0.05), (False, True)),  # 6 % in frequency: beyond the reach of 5 %
    ((5.0, 9.1), (0.1, 0.08), (True, False)),  # 60 % in damping: beyond 50 %
])  # fmt: skip
def test_a_band_limited_refit_is_reported_within_its_reach_else_the_armax_value_stays(freq_hz, damping, reported):
    import armaxmodal.modes.state as st

    modes = _modes([5.0, 9.0], [0.1, 0.05], [1.0, 1.0]).assign(estimator="armax", freq_sd=0.5, damping_sd=0.5)
    refit_shapes = np.array([[1.0, 0.2], [0.3, 1.0]], dtype=complex)
    ref = _band_limited_refit(freq_hz, damping, refit_shapes)
    out = st.refined_modes(SelectionState(modes, np.eye(2, dtype=complex)), ref, 0.05, 0.5)
    assert out.refinement is ref and len(out.modes) == 2
    for i, taken in enumerate(reported):
        expected = (freq_hz[i], damping[i], 1e-3 * freq_hz[i]) if taken else (modes.freq_hz[i], modes.damping[i], 0.5)
        assert tuple(out.modes.loc[i, ["freq_hz", "damping", "freq_sd"]]) == pytest.approx(expected)
        assert out.modes.estimator[i] == ("fd-bandlimited" if taken else "armax (refit moved too far)")
        np.testing.assert_array_equal(out.shapes[:, i], refit_shapes[:, i] if taken else np.eye(2)[:, i])


def test_two_modes_a_band_limited_refit_brings_together_stay_two_for_the_count():
    """5.00 and 5.25 Hz refitted to 5.10 and 5.12 Hz: both stay, for the count to judge (the refit
    merged them until 2026-12-07, and ``n_modes`` could come back short)."""
    import armaxmodal.modes.state as st

    modes = _modes([5.0, 5.25], [0.1, 0.1], [0.5, 1.0]).assign(estimator="armax", freq_sd=0.5, damping_sd=0.5)
    ref = _band_limited_refit([5.10, 5.12], [0.1, 0.1], np.eye(2, dtype=complex))
    out = st.refined_modes(SelectionState(modes, np.eye(2, dtype=complex)), ref, 0.05, 0.5)
    assert out.modes.freq_hz.tolist() == [5.10, 5.12] and out.shapes.tolist() == [[1.0, 0.0], [0.0, 1.0]]


def test_filled_samples_widen_every_interval_by_the_information_they_lack():
    """720 of 7,200 samples filled: the intervals widen by sqrt(7200 / 6480) about each value (a
    damping ratio's on its logarithm), the other structures' part included (an asymmetric interval
    stays asymmetric)."""
    from types import SimpleNamespace

    from armaxmodal.modes.result import filled_samples_scale as _filled_samples_scale

    filled = am.QualityWarning("gap_filled", ("head",), "x", 700.0)
    bridged = am.QualityWarning("dropped_packet", ("head",), "y", 20.0)
    rec = SimpleNamespace(duration=120.0, fs=20.0, meta={"read_warnings": [filled, bridged]})
    modes = pd.DataFrame({"freq_hz": [5.0], "freq_sd": [0.1 / Z95], "freq_other_hi": [5.2], "damping": [0.1],
                          "damping_sd": [0.01 / Z95], "damping_other_hi": [0.1]})  # fmt: skip
    k, (note,) = _filled_samples_scale(rec, SimpleNamespace(original_fs=60.0))  # resampled 60 -> 20 Hz
    assert k == pytest.approx(np.sqrt(7200 / 6480)) and note.value == k
    out = with_intervals(modes, k)
    np.testing.assert_allclose(out[["freq_ci95_lo", "freq_ci95_hi"]].to_numpy(), [[5 - 0.1 * k, 5 + 0.2 * k]])
    damping_ci = out[["damping_ci95_lo", "damping_ci95_hi"]].to_numpy()
    np.testing.assert_allclose(damping_ci, [[0.1 * np.exp(-0.1 * k), 0.1 * np.exp(0.1 * k)]])
    rec.meta = {}
    assert _filled_samples_scale(rec, None) == (1.0, [])
