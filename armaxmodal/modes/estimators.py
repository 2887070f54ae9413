"""Two estimators of the same modes that the record shows to disagree: the intervals cover both.

The selection estimates every mode twice before it reports it: first the diagram's ARMAX fit (or
its band-limited refit, where the record is band-limited), then the maximum-likelihood modal model
that counts the modes (:mod:`armaxmodal.modes.counted`). For a linear structure and the noise each
of them weights by, both are consistent, and their differences are noise: each

    z = (value - earlier) / sqrt(sd^2 + sd_earlier^2)

is at most standard normal (the two fits share the record, so the difference varies less than the
sum of the variances says). Where the sum of ``z^2`` over every mode's frequency and damping ratio
exceeds the ``estimators_alpha`` (1 %) point of its chi-squared distribution -- Hausman's specification test
(Econometrica 46 (1978) 1251), with the two estimates taken as independent, which makes it
conservative -- one of them is biased on this record: by model error the two weight differently
(a nonlinearity, a hold the model lacks, leakage), or by diagram orders too low for a mode (a light
chain's top mode, 10 of its SDs off in the ARMAX fit). One record cannot say which is then right,
so every mode's 95 % interval covers the earlier estimator's 95 % interval too (the
``{q}_estimator_lo/hi`` parts of :mod:`armaxmodal.modes.intervals`), and an
``estimators_disagree`` note gives the statistic.

Why a test on the record, not on each mode: the model error is the record's (the F-16's joint
distorts every mode it moves), and a mode whose own difference is 1.8 standard deviations carries
it as much as one at 3.6. On the F-16's four multisine levels the statistic is 58, 59, 30 and 38
for 12 degrees of freedom (1 % point 26.2); the intervals before covered the earlier estimate in
14 of 24 modes.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import scipy.stats

from armaxmodal.modes.intervals import QUANTITIES
from armaxmodal.modes.settings import DEFAULTS
from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.stats import Z95

__all__ = ["EARLIER_COLUMNS", "covering_both_estimators", "earlier_estimate"]

#: the columns a counted row keeps of the selection's earlier estimate of its mode
EARLIER_COLUMNS = tuple(f"{q}_{part}" for q, _ in QUANTITIES for part in ("earlier", "earlier_sd"))


def earlier_estimate(row: dict) -> dict:
    """The selection's estimate of a mode (``row``: a selection row as the diagram's ARMAX fit or
    the band-limited refit left it) as the ``{q}_earlier``, ``{q}_earlier_sd`` columns; all NaN
    where the row is the modal model's already (``estimator`` ``ml-...``)."""
    mine = not str(row.get("estimator", "")).startswith("ml-")
    columns = {}
    for q, value in QUANTITIES:
        columns[f"{q}_earlier"] = float(row[value]) if mine else np.nan
        # a row without a deviation (no interval of its own) is not tested: its z is NaN
        columns[f"{q}_earlier_sd"] = float(row.get(f"{q}_sd", np.nan)) if mine else np.nan
    return columns


def covering_both_estimators(rows: pd.DataFrame, alpha: float = DEFAULTS.intervals.estimators_alpha
                             ) -> tuple[pd.DataFrame, list[QualityWarning]]:  # fmt: skip
    """Counted ``rows`` (with :data:`EARLIER_COLUMNS`) with their intervals covering the earlier
    estimator's where the record shows the two disagree (the module's docstring).

    Parameters
    ----------
    rows : DataFrame
        The counted modes: ``freq_hz``, ``damping``, ``freq_sd``, ``damping_sd`` and the
        earlier estimate's columns (NaN where a mode has none).
    alpha : float
        The test's level (:class:`~armaxmodal.modes.settings.IntervalSettings`).

    Returns
    -------
    (DataFrame, list of QualityWarning)
        A copy with ``{q}_estimator_lo``, ``{q}_estimator_hi`` (the earlier estimate's 95 %
        interval where the test rejects, else NaN) and ``estimator_widened`` (the interval
        reaches beyond the mode's own); an ``estimators_disagree`` note when the test rejects.
    """
    out = rows.copy()
    for column in EARLIER_COLUMNS:  # rows from the selection itself (a pick the model left) have none
        if column not in out:
            out[column] = np.nan
    z = []
    for q, value in QUANTITIES:
        out[f"{q}_estimator_lo"] = out[f"{q}_estimator_hi"] = np.nan
        diff = out[value].to_numpy(float) - out[f"{q}_earlier"].to_numpy(float)
        z.append(diff / np.hypot(out[f"{q}_sd"].to_numpy(float), out[f"{q}_earlier_sd"].to_numpy(float)))
    z = np.concatenate(z)
    z = z[np.isfinite(z)]
    out["estimator_widened"] = False
    if z.size == 0:
        return out, []
    statistic, critical = float(np.sum(z**2)), float(scipy.stats.chi2.isf(alpha, z.size))
    if statistic <= critical:
        return out, []
    widened = np.zeros(len(out), dtype=bool)
    for q, value in QUANTITIES:
        earlier, sd = out[f"{q}_earlier"].to_numpy(float), out[f"{q}_earlier_sd"].to_numpy(float)
        lo, hi = earlier - Z95 * sd, earlier + Z95 * sd
        out[f"{q}_estimator_lo"], out[f"{q}_estimator_hi"] = lo, hi
        v, own = out[value].to_numpy(float), Z95 * out[f"{q}_sd"].to_numpy(float)
        widened |= np.isfinite(lo) & ((lo < v - own) | (hi > v + own))
    out["estimator_widened"] = widened
    where = ", ".join(f"{f:.3f}" for f in out.freq_hz[widened])
    note = QualityWarning(
        "estimators_disagree", (),
        f"the modal model's modes and the diagram's fit of them differ beyond their noise (sum of squared "
        f"standardised differences {statistic:.1f} for {z.size} values, its {100 * (1 - alpha):g} % point "
        f"{critical:.1f}): one of them is biased here, by model error the two weight differently (a nonlinearity, the "
        "inter-sample behaviour, leakage) or by orders too low for a mode. One record cannot say which, so every "
        "mode's interval covers both estimates"
        + (f"; widened at {where} Hz" if where else ""),
        statistic,
    )  # fmt: skip
    return out, [note]
