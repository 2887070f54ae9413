"""Channels out of time: a sensor or the input late (or early) against the others.

Two tests. The phase slope of the quasi-static transmissibility times a delay to a fraction
of a sample whatever ``nk`` the model needed (``delay_findings``); the residual-input
cross-correlation beyond the model's non-causal taps finds leads too long for that slope
(``lead_findings``). Outputs that lag alike -- a delay within the spread their own
intervals allow -- are one effect on the input, named once with one delay and its interval:
moving one channel explains them all, and it is the recorder's offset between the base and
the body, not four sensors' faults.
"""

from __future__ import annotations

import numpy as np
from scipy import stats
from scipy.special import stdtrit

from armaxmodal.diagnosis.finding import Finding
from armaxmodal.diagnosis.model import FittedModel, usable
from armaxmodal.prepare.delay import MIN_DELAY_SAMPLES, DelayEstimate, estimate_delays, jackknife_sd
from armaxmodal.recording import Recording

__all__ = ["delay_findings", "lead_findings", "cross_correlation", "late_start", "pooled", "SPREAD_ALPHA"]

#: Outputs whose delays scatter no more than this test's chance (chi-square of their spread
#: about the common delay, each by its own interval) lag alike.
SPREAD_ALPHA = 0.01

#: Lags of the residual-input cross-correlation searched for an output that leads the input
#: beyond the model's non-causal taps (an IMU on its own clock: 15-22 samples on the shake table).
LEAD_MAX_LAG = 40
#: lags just past the model's reach left out of that search: a band-limited response's
#: non-causal tail runs on past any finite nk, and a distorted fit (a drift, a missing mode)
#: leaks into the first lags there (an offset on chest once read as head 6 samples ahead of
#: nk = -5; after a line fix, head 8 samples ahead of nk = -3). Leads that short are the
#: phase slope's to time; this test is for clocks off by more (IMUs: 15-22 samples).
LEAD_GUARD = 6


def delay_findings(fitted: FittedModel, n_tests: int) -> list[Finding]:
    """A sensor or the input out of time, from the quasi-static transmissibility phase
    (:func:`armaxmodal.prepare.delay.estimate_delays`): its slope is the time offset whatever ``nk``
    the model needed, and a held input's half sample stays under the reporting floor.

    Every output late (or early) alike is one finding on the input (:func:`_common_delay`);
    ``delay_samples`` is always how late the named channel is (negative on the input: the
    outputs lag it), the amount the fix moves it earlier."""
    s = fitted.signals
    rec = Recording(s.fs, s.u, s.y, s.sensors, s.input_name)
    late = []
    for e in estimate_delays(rec):
        z = abs(e.delay_s) / max(e.delay_sd_s, 1e-300)
        p = min(1.0, 2 * stats.t.sf(z, max(e.dof, 1)) * n_tests)  # the sd has few degrees of freedom
        if abs(e.delay_s) * s.fs >= MIN_DELAY_SAMPLES:
            late.append((e, p))
    if not late:
        return []
    same_sign = all(e.delay_s > 0 for e, _ in late) or all(e.delay_s < 0 for e, _ in late)
    if len(late) == len(s.sensors) > 1 and same_sign:
        common = _common_delay([e for e, _ in late], s.fs)
        if common is not None:
            return [_input_finding(common, max(p for _, p in late), s)]
    return [_output_finding(e, p, s.fs) for e, p in late]


def _output_finding(e: DelayEstimate, p: float, fs: float) -> Finding:
    half = e.quantile(0.975) * e.delay_sd_s
    params = {
        "delay_ms": 1e3 * e.delay_s,
        "delay_ci95_ms": [1e3 * (e.delay_s - half), 1e3 * (e.delay_s + half)],
        "delay_samples": e.delay_s * fs,
    }
    return Finding("input_delay", (e.channel,), "phase_slope_z", e.delay_s / e.delay_sd_s, p, params)


def _input_finding(common: dict, p: float, s) -> Finding:
    """The common delay as the input's: an output lag of d is the input d early."""
    lag, lo, hi = common["lag_s"], common["lag_ci95_s"][0], common["lag_ci95_s"][1]
    params = {
        "delay_ms": -1e3 * lag,
        "delay_ci95_ms": [-1e3 * hi, -1e3 * lo],
        "delay_samples": -lag * s.fs,
        "outputs_lag_ms": 1e3 * lag,
        "outputs_lag_ci95_ms": [1e3 * lo, 1e3 * hi],
        "per_output_lag_ms": {k: 1e3 * v for k, v in common["per_output_s"].items()},
        "spread_p": common["spread_p"],
    }
    return Finding("input_delay", (s.input_name,), "phase_slope_z", lag / common["sd_s"], p, params)


def _common_delay(estimates: list[DelayEstimate], fs: float) -> dict | None:
    """One delay for outputs that lag alike, or None for a spread.

    Alike: Cochran's Q, the chi-square of the delays about their inverse-variance mean, is
    within chance (``SPREAD_ALPHA``), or they differ by less than the reporting floor. The
    common delay is the random-effects mean (DerSimonian-Laird): each output's phase slope
    carries a bias of its own from the structure's phase (on the clean supine ride they read
    -0.9 to +0.2 ms), which Q measures as spread beyond the intervals; a fixed-effect mean
    ignored it, and its interval missed a planted 50 ms delay. Its standard deviation is the
    larger of that and a jackknife of the mean over the same left-out blocks of segments
    (the outputs share the input's noise, so their errors correlate)."""
    d = np.array([e.delay_s for e in estimates])
    w = 1.0 / np.array([max(e.delay_sd_s, 1e-300) for e in estimates]) ** 2
    _, _, q, spread_p = pooled(d, np.sqrt(1.0 / w))
    if spread_p < SPREAD_ALPHA and np.ptp(d) * fs >= MIN_DELAY_SAMPLES:
        return None
    tau2 = max(0.0, (q - (d.size - 1)) / (w.sum() - (w @ w) / w.sum()))
    w = 1.0 / (1.0 / w + tau2)
    mean = float(w @ d / w.sum())
    sd, dof = float(1.0 / np.sqrt(w.sum())), min(e.dof for e in estimates)
    if len({len(e.left_out) for e in estimates}) == 1:  # the same blocks for every output
        blocks = np.array([e.left_out for e in estimates]).reshape(d.size, -1)
        means = (w @ blocks[:, np.all(np.isfinite(blocks), axis=0)]) / w.sum()
        if means.size >= 3:
            jackknife = jackknife_sd(means)
            if jackknife > sd:
                sd, dof = jackknife, means.size - 1
    half = float(stdtrit(max(dof, 1), 0.975)) * sd
    return {
        "lag_s": mean,
        "sd_s": sd,
        "lag_ci95_s": [mean - half, mean + half],
        "per_output_s": {e.channel: e.delay_s for e in estimates},
        "spread_p": spread_p,
    }


def pooled(values: np.ndarray, sds: np.ndarray) -> tuple[float, float, float, float]:
    """``(mean, sd, q, spread_p)``: the inverse-variance mean of estimates ``values`` (k,) with SDs
    ``sds`` (k,), its SD, and Cochran's Q of their spread about it with its chi-square p (k - 1
    degrees of freedom): are they one quantity measured k times?"""
    w = 1.0 / np.asarray(sds, float) ** 2
    mean = float(w @ values / w.sum())
    q = float(w @ (np.asarray(values, float) - mean) ** 2)
    return mean, float(1.0 / np.sqrt(w.sum())), q, float(stats.chi2.sf(q, len(values) - 1))


def late_start(fitted: FittedModel, findings: list[Finding]) -> dict[str, int]:
    """``{output: samples}``: how many first samples of each output a delay explains (the
    fix's shifts and this round's delay findings). A recorder that starts a late channel fills
    its first samples (zeros, or the first reading held): that run is the delay's, not a
    stuck sensor's."""
    s = fitted.raw
    lateness = {name: 0.0 for name in s.sensors}
    delays = [(name, d) for name, d in fitted.spec.shifts]
    delays += [(f.channels[0], f.parameters["delay_samples"]) for f in findings if f.effect == "input_delay"]
    for name, d in delays:
        if name == s.input_name:  # the input early by -d: every output late by -d
            for out in lateness:
                lateness[out] = max(lateness[out], -d)
        elif name in lateness:
            lateness[name] = max(lateness[name], d)
    return {name: int(np.ceil(d)) + 1 for name, d in lateness.items() if d > 0}


def lead_findings(fitted: FittedModel, n_tests: int, timed: set) -> list[Finding]:
    """An output ahead of the input by more than the model's non-causal taps reach, where the
    quasi-static phase slope cannot time it (no quasi-static band, as on IMUs): its one-step
    residual correlates with *future* input beyond lag ``nk`` (MATLAB ``resid``'s region, with
    the bound of :func:`cross_correlation`; Bonferroni over those lags, sensors and tests). The
    lead is the lag of the largest correlation there -- the direct term of an acceleration
    transmissibility puts it at the first future sample the output answers. Every output
    ahead by the same amount is the input being late. Sensors already timed are left alone."""
    s = fitted.signals
    ccf = cross_correlation(fitted, LEAD_MAX_LAG)
    lags = np.asarray(ccf["lags"])
    beyond = lags < min(fitted.spec.orders[3], 0) - LEAD_GUARD
    if not beyond.any():
        return []
    found = []
    for k, name in enumerate(s.sensors):
        if name in timed:
            continue
        z = np.abs(np.asarray(ccf["ccf"][k])[beyond]) * stats.norm.ppf(0.995) / ccf["bound99"][k]
        i = int(np.argmax(z))
        p = min(1.0, 2 * float(stats.norm.sf(z[i])) * int(beyond.sum()) * n_tests)
        found.append((name, float(-lags[beyond][i]), float(z[i]), p))
    leading = [f for f in found if f[3] < 0.01]
    if len(leading) == len(s.sensors) > 1 and np.ptp([f[1] for f in leading]) <= 1:
        lead = float(np.median([f[1] for f in leading]))
        return [_lead_finding(s.input_name, lead, max(f[2] for f in leading), max(f[3] for f in leading), s.fs)]
    return [_lead_finding(name, -lead, z, p, s.fs) for name, lead, z, p in found]


def _lead_finding(channel: str, delay_samples: float, z: float, p: float, fs: float) -> Finding:
    """An ``input_delay`` finding from the cross-correlation (whole samples, no interval)."""
    params = {
        "delay_samples": delay_samples,
        "delay_ms": 1e3 * delay_samples / fs,
        "method": "residual-input cross-correlation beyond the model's non-causal taps",
    }
    return Finding("input_delay", (channel,), "residual_input_ccf_z", z, p, params)


def cross_correlation(fitted: FittedModel, max_lag: int = 25) -> dict:
    """Residual-input cross-correlation at lags -max_lag..max_lag with its 99 % bound (the
    region of MATLAB's ``resid``): the bound uses both autocorrelations, as the input is
    coloured."""
    s = fitted.signals
    mask = usable(s.n, fitted.spec)
    eps = fitted.one_step_errors()[mask]
    u = s.u[mask] - s.u[mask].mean()
    n = u.size
    lags = np.arange(-max_lag, max_lag + 1)
    ru = np.correlate(u, u, "full")[n - 1 : n + 2 * max_lag] / (u @ u)
    out = {"lags": lags.tolist(), "ccf": [], "bound99": []}
    for k in range(eps.shape[1]):
        e = eps[:, k] - eps[:, k].mean()
        full = np.correlate(e, u, "full") / np.sqrt((e @ e) * (u @ u))
        ccf = full[n - 1 + lags]
        re = np.correlate(e, e, "full")[n - 1 : n + 2 * max_lag] / (e @ e)
        p1 = 1 + 2 * float(np.sum(re[1:] * ru[1:]))
        out["ccf"].append(ccf.tolist())
        out["bound99"].append(float(stats.norm.ppf(0.995) * np.sqrt(max(p1, 1e-3) / n)))
    return out


#: Candidate nonlinear restoring forces of a deflection ``d``.
