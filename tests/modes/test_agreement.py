"""Does the record agree with itself: its halves, its segments and its two estimators, asked at one
level (``AgreementSettings``). The halves' statistic by hand, its pooling over a trial's new poles,
and the one level reaching all three tests."""

from types import SimpleNamespace

import numpy as np
import pytest
from scipy.special import chdtrc

import armaxmodal as am
from armaxmodal.modes.count_search import _Search
from armaxmodal.modes.mode_count import halves_chi2
from armaxmodal.modes.settings import AgreementSettings, ClusterSettings, DftSettings, SelectionSettings


class _Half:
    """A half's lines as the halves' test sees them: weighted (as the record's), then fitted;
    ``power``: its sensors' power near each frequency (Hz: power), 1 where not given."""

    def __init__(self, name, power=None):
        self.name, self.power = name, power or {}

    def weighted(self, weights):
        return self

    def response_power(self, freq_hz, reach):
        assert reach == ClusterSettings().freq  # where a half's pole is the mode's: the clustering's reach
        return self.power.get(float(freq_hz), 1.0)


def _fit(freq_hz, damping, freq_sd, damping_sd):
    return SimpleNamespace(freq_hz=np.asarray(freq_hz, float), damping=np.asarray(damping, float),
                           freq_sd=np.asarray(freq_sd, float), damping_sd=np.asarray(damping_sd, float))  # fmt: skip


#: two poles; each half's deviations make the differences' deviations 0.05 Hz and 0.01
FITS = {
    "first": _fit([5.0, 10.0], [0.10, 0.20], [0.03, 0.03], [0.006, 0.006]),
    # listed the other way round: each half's pole is the one nearest the model's
    "second": _fit([10.05, 5.1], [0.21, 0.13], [0.04, 0.04], [0.008, 0.008]),
}
MODEL = SimpleNamespace(freq_hz=np.array([5.0, 10.0]), damping=np.array([0.1, 0.2]), n_modes=2)
HALVES = (_Half("first"), _Half("second"))


SEEN = []


def _fitter(data, freq_hz, damping, hold, max_nfev, settings):
    SEEN.append((hold, max_nfev, settings, tuple(freq_hz)))
    return FITS[data.name]


def test_the_halves_statistic_sums_both_values_squared_differences():
    # 5 Hz: 0.1 Hz apart (2 SD), damping 0.03 apart (3 SD): 4 + 9; 10 Hz: 1 SD each: 1 + 1
    SEEN.clear()
    slow = DftSettings(fit_tol=1e-9)
    chi2 = halves_chi2(SimpleNamespace(weights=1.0), MODEL, HALVES, "zoh", 17, slow, fitter=_fitter)
    assert chi2 == pytest.approx([13.0, 2.0])
    assert SEEN == [("zoh", 17, slow, (5.0, 10.0))] * 2  # each half fitted from the model's poles, as asked


@pytest.mark.parametrize(
    ("new", "alpha", "statistic", "agree"),
    [
        ([1], 0.01, 2.0, True),  # 2 for 2 degrees of freedom: p = e^-1
        ([0], 0.01, 13.0, False),  # 13 for 2: p = 1.5e-3 (no value beyond 3 SD: the larger-of-two rule took it)
        ([0], 1e-3, 13.0, True),  # the same at a level of 0.1 %
        ([0, 1], 0.01, 15.0, False),  # 15 for 4, pooled: p = 4.7e-3
        ([0, 1], 4e-3, 15.0, True),
    ],
)
def test_the_count_pools_a_trials_new_poles_at_the_one_level(new, alpha, statistic, agree):
    SEEN.clear()
    slow = DftSettings(fit_tol=1e-9)
    search = _Search(SimpleNamespace(weights=1.0), "bandlimited", 1e4, 23, dft=slow, fitter=_fitter,
                     agreement=AgreementSettings(alpha=alpha))  # fmt: skip
    assert search.in_both_halves(MODEL, new, HALVES) is agree
    assert search.p == pytest.approx(chdtrc(2 * len(new), statistic)) and search.trials == 2
    assert {seen[:3] for seen in SEEN} == {("bandlimited", 23, slow)}  # the search's own fits' settings
    search.in_both_halves(MODEL, new, HALVES)
    assert search.trials == 4  # two fits a test


def test_a_pole_one_half_does_not_excite_is_not_tested_by_the_halves():
    """A sweep passes the 10 Hz mode in the first half only: the sensors' power there in the second is
    0.5 % of the first's, below the 1 % the halves need; at 2 % it is tested again."""
    swept = (_Half("first"), _Half("second", {10.0: 0.005}))
    chi2 = halves_chi2(SimpleNamespace(weights=1.0), MODEL, swept, "zoh", 17, fitter=_fitter)
    assert chi2[0] == pytest.approx(13.0) and np.isnan(chi2[1])
    search = _Search(SimpleNamespace(weights=1.0), "zoh", 1e4, 40, fitter=_fitter)
    assert search.in_both_halves(MODEL, [1], swept) is None  # not asked: neither agreed nor refused
    assert search.p == 1.0
    assert search.in_both_halves(MODEL, [0, 1], swept) is False  # pooled over the tested pole alone: 13 for 2
    assert search.p == pytest.approx(chdtrc(2, 13.0))
    barely = (_Half("first"), _Half("second", {10.0: 0.02}))
    assert halves_chi2(SimpleNamespace(weights=1.0), MODEL, barely, "zoh", 17, fitter=_fitter)[1] == pytest.approx(2.0)
    strict = AgreementSettings(excitation_ratio=0.03)
    assert np.isnan(halves_chi2(SimpleNamespace(weights=1.0), MODEL, barely, "zoh", 17, fitter=_fitter,
                                agreement=strict)[1])  # fmt: skip


def test_a_trial_with_no_new_pole_agrees():
    search = _Search(SimpleNamespace(weights=1.0), "zoh", 1e4, 40, fitter=_fitter)
    assert search.in_both_halves(MODEL, [], HALVES) is True and search.p == 1.0


def test_the_one_level_reaches_the_estimators_test(bundled_diagram):
    """On the bundled ride the two estimators agree at 1 %; at a level of 1 every difference is too
    many (the chi-square's 100 % point is 0)."""
    diagram = bundled_diagram
    default = am.select_modes(diagram, n_jobs=1, segments=0)
    every = am.select_modes(diagram, n_jobs=1, segments=0, settings=SelectionSettings(agreement=AgreementSettings(1.0)))
    assert default.quality == "good" and "estimators_disagree" not in {w.code for w in default.warnings}
    assert "estimators_disagree" in {w.code for w in every.warnings} and every.settings.agreement.alpha == 1.0


def test_the_one_level_reaches_the_segments_test():
    """A ride stiffer by 12 % in its second half: its first mode's segments scatter far beyond the
    1 % test's point (and are flagged there, ``test_segment_spread``), but not beyond 1e-40's."""
    from scipy.special import chdtri

    fs, body = 60.0, am.supine_human()
    parts = [am.simulate_recording(s, am.random_vibration(fs, 60.0, (0.5, 28.0), seed=k), fs, noise=0.05, hold="zoh",
                                   seed=k + 100) for k, s in ((1, body), (2, am.Structure(body.M, body.C, body.K * 1.12,
                                                                                           body.names)))]  # fmt: skip
    rec = am.Recording(fs, np.concatenate([p.base for p in parts]), np.vstack([p.response for p in parts]),
                       parts[0].sensors)  # fmt: skip
    strict = SelectionSettings(agreement=AgreementSettings(alpha=1e-40))
    modes = am.select_modes(am.stabilisation_diagram(rec, per_sensor=False), segments=3, settings=strict).modes
    statistic = 2 / 3 * (modes.freq_segment_sd / modes.freq_sd_armax) ** 2  # three segments
    assert statistic.max() > chdtri(2, 0.01 / (2 * len(modes)))
    assert statistic.max() < chdtri(2, 1e-40 / (2 * len(modes))) and not modes.model_error_dominates.any()
