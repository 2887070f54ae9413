"""The stabilisation diagram's rules on small hand-made pole tables: classes between
consecutive orders, clustering across orders, merging of split modes, the order cap and the
delay-edge warning, and the refit's hand-over. Each expected value follows from the rule's
definition in :mod:`armaxmodal.stabilisation`; no fit runs, so these also serve the mutation
run (mutmut) over that module."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import armaxmodal as am
from armaxmodal.exceptions import OrderError
from armaxmodal.stabilisation import (
    SAMPLES_PER_PARAMETER,
    Tolerances,
    _apply_refinement,
    _check_top_order,
    _classify,
    _cluster,
    _merge_duplicates,
    _nk_edge_warning,
    _supported,
)

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
    assert _classify(poles, Tolerances()) == ["new", "new", "f+d+v", "f+d", "f", "new"]


def test_single_sensor_classes_compare_residue_magnitudes():
    poles = _poles(
        [
            ("head", 2, 5.0, 0.1, [1.0]),
            ("head", 4, 5.0, 0.1, [1.09j]),  # |r| within 10 %: same
            ("head", 6, 5.0, 0.1, [1.30]),  # 19 % larger than the order before: not
            ("chest", 2, 5.0, 0.1, [1.0]),  # another source starts its own chain
        ]
    )
    assert _classify(poles, Tolerances()) == ["new", "f+d+v", "f+d", "new"]


def test_clusters_take_one_pole_per_order_within_frequency_and_damping():
    rows = []
    for na in (2, 4, 6, 8):
        rows += [("shared", na, 5.0 * (1 + 0.004 * na), 0.10, SHAPE), ("shared", na, 9.0, 0.02, SHAPE)]
    rows += [("shared", 8, 5.1, 0.10, SHAPE)]  # a second pole near 5 Hz at na = 8: its own cluster
    rows += [("shared", 6, 9.05, 0.05, SHAPE)]  # damping 150 % off the 9 Hz cluster's
    poles = _poles(rows).assign(energy=1.0)
    clusters = _cluster(poles, [2, 4, 6, 8], 0.05, 0.5)
    sizes = sorted(len(c) for c in clusters)
    assert sizes == [1, 1, 4, 4]
    for c in clusters:
        assert poles.loc[c, "na"].is_unique
    # by frequency alone the odd-damping pole joins nothing new: the 9 Hz cluster has its na = 6 already
    assert sorted(len(c) for c in _cluster(poles, [2, 4, 6, 8], 0.05, None)) == [1, 1, 4, 4]
    assert _supported(3, 7, 0.4) and not _supported(2, 4, 0.4) and not _supported(3, 10, 0.4)


def _modes(freqs, dampings, support):
    return pd.DataFrame(
        {"freq_hz": freqs, "damping": dampings, "support": support, "count": [10] * len(freqs), "energy": 1.0}
    )


def test_split_modes_merge_within_resolution_or_bandwidth_with_alike_shapes():
    other = np.array([1.0, -1.0, 0.3 + 0.0j])
    # 10.00 and 10.15 Hz at 2 % damping (half-power 0.4 Hz): alike shapes merge, unlike stay
    modes = _modes([10.0, 10.15], [0.02, 0.02], [1.0, 0.6])
    assert _merge_duplicates(modes, [SHAPE, SHAPE * 1j], 0.8, 60.0) == [0]
    assert _merge_duplicates(modes, [SHAPE, other], 0.8, 60.0) == [0, 1]
    # within 2 / T (T = 10 s: 0.2 Hz) nothing tells them apart, whatever the shapes
    assert _merge_duplicates(modes, [SHAPE, other], 0.8, 10.0) == [0]
    # beyond the bandwidth they are two modes; the weaker survives when it is the first
    far = _modes([10.0, 10.6], [0.02, 0.02], [0.5, 1.0])
    assert _merge_duplicates(far, [SHAPE, SHAPE], 0.8, 60.0) == [0, 1]
    assert _merge_duplicates(_modes([10.0, 10.15], [0.02, 0.02], [0.5, 1.0]), [SHAPE, SHAPE], 0.8, 60.0) == [1]


def _recording(n: int) -> am.Recording:
    rng = np.random.default_rng(n)
    return am.Recording(60.0, rng.standard_normal(n), rng.standard_normal((n, 1)), ("a",))


def test_delay_edge_warning_only_at_the_end_of_the_search():
    rec = _recording(100)
    (w,) = _nk_edge_warning(-9, rec)
    assert w.code == "nk_at_search_edge" and w.value == -9.0 and w.channels == ("base",)
    assert _nk_edge_warning(-8, rec) == [] and _nk_edge_warning(0, rec) == []


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
        estimator="armax", damped_freq_hz=0.0, freq_ci95_lo=0.0, freq_ci95_hi=0.0, damping_ci95_lo=0.0,
        damping_ci95_hi=0.0,
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
    assert out.estimator.tolist() == ["fd-bandlimited", "armax (refit moved too far)"]
    assert out.at[0, "freq_hz"] == 5.1 and out.at[0, "damping"] == 0.12
    assert out.at[0, "damped_freq_hz"] == pytest.approx(5.1 * np.sqrt(1 - 0.12**2))
    assert (out.at[0, "freq_ci95_lo"], out.at[0, "freq_ci95_hi"]) == pytest.approx((5.1 - 0.0196, 5.1 + 0.0196))
    damping_ci = (out.at[0, "damping_ci95_lo"], out.at[0, "damping_ci95_hi"])
    assert damping_ci == pytest.approx((0.12 - 0.00392, 0.12 + 0.00392))
    assert out.at[1, "freq_hz"] == 9.0
    np.testing.assert_array_equal(out_shapes[:, 0], ref.shapes[:, 0])
    np.testing.assert_array_equal(out_shapes[:, 1], shapes[:, 1])
    assert modes.at[0, "freq_hz"] == 5.0  # the input table is not changed
    # damping moved by more than half: the ARMAX value stays
    ref.damping = np.array([0.16, 0.05])
    assert _apply_refinement(modes, shapes, ref, 0.05, 0.5)[0].estimator[0] == "armax (refit moved too far)"
