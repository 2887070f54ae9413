"""Statistical tests of a fitted model's residual, each a statistic with a p-value.

In-sample least-squares residuals are orthogonal to the model's own regressors, so a plain
regression of the residual on a candidate would understate it; the in-sample tests here are
score (LM) tests in their F form: the residual regressed on the model's gradient columns and
the candidate together (Breusch-Godfrey for whiteness, the same for trend terms). Whether a
fix is kept is decided on held-out data elsewhere (:mod:`.acceptance`); which tests a
round runs, and in what order, is the registry's (:mod:`.effects`).

Every p-value is corrected for the number of sensors times tests (Bonferroni), so the
chance of naming any effect on a clean recording stays near ``alpha``.
"""

from __future__ import annotations

import numpy as np
from scipy import stats
from scipy.signal import lfilter

from armaxmodal.diagnosis.clipping import rail_pileup
from armaxmodal.diagnosis.faults import (
    FAULT_ALPHA,
    FOLLOWS_ALPHA,
    follows_excitation,
    glitch_p,
    glitches,
    input_rail_reach,
    outlier_scores,
    shared_by_others,
    stuck_runs,
)
from armaxmodal.diagnosis.finding import Finding
from armaxmodal.diagnosis.model import LINE_MERGE_HZ, UNDAMPED, FittedModel, usable
from armaxmodal.diagnosis.model import lagged as _lag
from armaxmodal.diagnosis.spectral import harmonic_f_test
from armaxmodal.estimate.fit import record_supports
from armaxmodal.prepare.quality import input_coherence
from armaxmodal.stats import MAX_DAMPING, SECOND_INPUT_COHERENCE

__all__ = [
    "clipping_findings",
    "fault_findings",
    "gradient_columns",
    "line_findings",
    "lm_f_test",
    "merge_per_sensor",
    "projected_f",
    "second_input_findings",
    "time_findings",
    "trend_findings",
    "whiteness_findings",
    "whiteness_p",
]

#: Lags of the residual in the Breusch-Godfrey whiteness test.
WHITENESS_LAGS = 10
#: Windows of the windowed re-identification (time variation).
N_WINDOWS = 6
#: A line in the residual is the input's (model error), not a disturbance, when the input
#: itself carries a line there at this significance. A real input line (a sine ride, a
#: multisine's component) gives p far below it; a random input reaches p < 1e-3 at 0.06-0.22 %
#: of its frequencies (three 120 s rides), and at 1e-3 a 0.3 m/s^2 hum at 12.5 Hz on the supine
#: fixture's legs went unnamed: the input read p = 7.7e-4 there by chance. None of 10^4
#: frequencies of those rides reached 1e-6.
INPUT_LINE_P = 1e-6


def gradient_columns(model, y: np.ndarray, u: np.ndarray, eps: np.ndarray) -> np.ndarray:
    """Columns of the one-step error's gradient of an ARMAX model, (n, na + n_in nb + nc):
    ``y(t-i)/C``, ``u(t-nk-j)/C`` and ``eps(t-i)/C`` (signs do not matter to a regression)."""
    na, nb, nc, nk = model.orders
    yc, ec = (lfilter([1.0], model.c, x) for x in (y, eps))
    uc = lfilter([1.0], model.c, u, axis=0).reshape(y.size, -1)
    cols = [_lag(yc, i) for i in range(1, na + 1)]
    cols += [_lag(uc[:, m], nk + j) for m in range(uc.shape[1]) for j in range(nb)]
    cols += [_lag(ec, i) for i in range(1, nc + 1)]
    return np.column_stack(cols)


def lm_f_test(eps: np.ndarray, psi: np.ndarray, z: np.ndarray) -> tuple[float, float]:
    """F form of the score test that ``z`` adds nothing to the regressors ``psi``: ``(F, p)``."""
    base = np.linalg.lstsq(psi, eps, rcond=None)[0]
    rss_r = float(np.sum((eps - psi @ base) ** 2))
    full = np.column_stack([psi, z])
    coef = np.linalg.lstsq(full, eps, rcond=None)[0]
    rss_u = float(np.sum((eps - full @ coef) ** 2))
    q, dof = z.shape[1], eps.size - full.shape[1]
    f = ((rss_r - rss_u) / q) / max(rss_u / dof, 1e-300)
    return f, float(stats.f.sf(f, q, dof))


def projected_f(e: np.ndarray, z: np.ndarray, p: int) -> tuple[float, float]:
    """:func:`lm_f_test` with the regressors already projected out of ``e`` and ``z``."""
    coef = np.linalg.lstsq(z, e, rcond=None)[0]
    rss_r, rss_u = float(e @ e), float(np.sum((e - z @ coef) ** 2))
    q, dof = z.shape[1], e.size - p - z.shape[1]
    f = ((rss_r - rss_u) / q) / max(rss_u / dof, 1e-300)
    return f, float(stats.f.sf(f, q, dof))


def merge_per_sensor(findings: list[Finding], effects) -> list[Finding]:
    """One finding per effect whose fix acts on every sensor (a trend, a richer C), listing
    each sensor where it is significant, strongest first."""
    out = [f for f in findings if f.effect not in effects]
    for effect in effects:
        group = sorted((f for f in findings if f.effect == effect), key=lambda f: f.p)
        if group:
            channels = tuple(c for f in group for c in f.channels)
            per_channel = {f.channels[0]: f.parameters for f in group}
            top = group[0]
            params = {**top.parameters, "per_channel": per_channel}
            out.append(Finding(effect, channels, top.statistic, top.value, top.p, params, payload=top.payload))
    return out


def clipping_findings(fitted: FittedModel, n_tests: int) -> list[Finding]:
    """A channel piled up at a rail beyond its own amplitude distribution (:mod:`.clipping`),
    tested on the recorded values; p corrected for both rails and for sensors x tests."""
    s = fitted.raw
    out = []
    for name, x in ((s.input_name, s.u), *zip(s.sensors, s.y.T, strict=True)):
        if name in fitted.spec.clipped:
            continue
        rails = rail_pileup(x)
        p = min(1.0, 2 * min(r[3] for r in rails) * n_tests)
        clipped = [r for r in rails if r[1] > 1 and r[3] < 1e-3]
        count = sum(r[1] for r in clipped) if clipped else max(r[1] for r in rails)
        params = {
            "samples": int(count),
            "percent": 100.0 * count / x.size,
            "rails": [r[0] for r in clipped],
            "expected_at_rail": [r[2] for r in clipped],
        }
        out.append(Finding("clipping", (name,), "rail_pileup", float(count), p, params))
    return out


def fault_findings(
    fitted: FittedModel, eps: np.ndarray, mask: np.ndarray, n_tests: int, delayed: dict[str, int]
) -> list[Finding]:
    """Per output, a stuck run or glitches (:mod:`.faults`); p corrected for sensors x tests.
    The payload is the recorded samples the fault spoiled: a stuck run's repeats (its first
    sample is the last live reading) and each glitch. A run at the start within the samples a
    delay explains (``delayed``, :func:`.delays.late_start`) is the late channel's fill."""
    raw, fs = fitted.raw, fitted.raw.fs
    shifts = dict(fitted.spec.shifts)
    known = {name: set(samples) for name, samples in fitted.spec.faults}
    out = []
    scores = np.column_stack([outlier_scores(eps[:, k], m, mask) for k, m in enumerate(fitted.fit.models)])
    for k, name in enumerate(raw.sensors):
        runs = [
            r
            for r in stuck_runs(raw.y[:, k])
            if r[0] + 1 not in known.get(name, ()) and not (r[0] == 0 and r[1] <= delayed.get(name, 0))
        ]
        lag = int(round(shifts.get(name, 0.0)))  # the residual is in the channel's shifted frame
        model = fitted.fit.models[k]
        spikes, sizes, largest = glitches(eps[:, k], model, mask & ~input_rail_reach(raw.u, model, lag))
        spikes = [t + lag for t in spikes if 0 <= t + lag < raw.n]
        p_follow = follows_excitation(spikes, raw.u, fs)
        p_shared = shared_by_others([t - lag for t in spikes], np.delete(scores, k, axis=1))
        if min(p_follow, p_shared) < FOLLOWS_ALPHA:  # strong motion or impacts: the structure's, not the sensor's
            spikes, sizes, largest = [], [], 0.0
        p_stuck = min((r[2] for r in runs), default=1.0)
        p_glitch = glitch_p(largest, int(mask.sum()))
        p = min(1.0, min(p_stuck, p_glitch) * n_tests)
        stuck = [r for r in runs if r[2] < FAULT_ALPHA]
        samples = sorted({t for first, stop, _ in stuck for t in range(first + 1, stop)} | set(spikes))
        params = {
            "stuck": [{"start_s": first / fs, "duration_s": (stop - first) / fs, "p": q} for first, stop, q in stuck],
            "glitches": len(spikes),
            "glitch_times_s": [t / fs for t in spikes[:20]],
            "glitch_sizes": sizes[:20],
            "samples": len(samples),
        }
        statistic, value = (
            ("stuck_run", float(max(r[1] - r[0] for r in runs)))
            if runs and p_stuck <= p_glitch
            else ("additive_outlier_z", largest)
        )
        out.append(Finding("sensor_fault", (name,), statistic, value, p, params, payload=tuple(samples)))
    return out


def trend_findings(fitted, eps, mask, n_tests, table) -> list[Finding]:
    """Offset and drift: score test of ``[1, t, t^2]`` (the terms the model does not yet have)
    filtered by ``A / C`` like the model's own disturbance regressors."""
    spec, s = fitted.spec, fitted.signals
    tau = np.linspace(-1.0, 1.0, s.n)
    terms = [d for d in range(3) if d > spec.trend_degree]
    out = []
    for k, m in enumerate(fitted.fit.models):
        y = s.y[:, k] - fitted.disturbance()[:, k]
        psi = gradient_columns(m, y, s.inputs(fitted.spec), eps[:, k])
        z = lfilter(m.a, m.c, np.column_stack([tau**d for d in terms]), axis=0)
        f, p = lm_f_test(eps[mask, k], psi[mask], z[mask])
        p = min(1.0, p * n_tests)
        table["trend_p"].append(p)
        if terms:
            coef = np.linalg.lstsq(np.column_stack([psi, z])[mask], eps[mask, k], rcond=None)[0][-len(terms) :]
            dur = s.n / s.fs
            params = {"offset": float(coef[0]) if terms[0] == 0 else 0.0}
            if 1 in terms:
                params["drift_per_s"] = float(coef[terms.index(1)]) * 2 / dur
            out.append(Finding("offset_drift", (s.sensors[k],), "score_F", f, p, params))
    return out


def line_findings(fitted, mask, n_tests, table) -> list[Finding]:
    """Spectral lines not coherent with the input (the input has no line there): Thomson's
    multitaper harmonic F-test on the simulation residual and on the output itself. A model
    of high enough order absorbs a line as an undamped pole pair; at such a pole's frequency
    the line is tested in the residual of the response without that pair
    (:func:`~.model.response_free_of`), corrected for those poles only."""
    from dataclasses import replace

    from armaxmodal.diagnosis.model import response_free_of

    s = fitted.signals
    resid = fitted.simulation_errors()[mask]
    u_test = harmonic_f_test(s.u[mask], s.fs)
    undamped = _undamped_pole_freqs(fitted)
    y_free = s.y - fitted.disturbance()
    pole_resid = {
        f: (
            y_free
            - response_free_of(
                replace(fitted.spec, lines_hz=fitted.spec.lines_hz + (f,)), fitted.fit, s.inputs(fitted.spec), y_free
            )
        )[mask]
        for f in undamped
    }
    out = []
    for k, name in enumerate(s.sensors):
        tests = [harmonic_f_test(resid[:, k], s.fs), harmonic_f_test(y_free[mask, k], s.fs)]
        # near an undamped pole the residual carries the spurious mode's own narrow response
        clean = [t for t in tests[:1] if not any(abs(t.freq_hz - f) < LINE_MERGE_HZ for f in undamped)]
        best = min(clean + tests[1:], key=lambda t: t.p_min)
        p, f0, f_val = 2 * best.p_min, best.freq_hz, best.f_max
        amp_test = tests[1]
        for f in undamped:
            at_pole = harmonic_f_test(pole_resid[f][:, k], s.fs)
            p_pole = 2 * len(undamped) * at_pole.p_at(f)
            if p_pole < p:
                p, f0, amp_test = p_pole, f, at_pole
                f_val = float(at_pole.f_stat[np.argmin(np.abs(at_pole.freqs - f))])
        p = min(1.0, p * n_tests)
        table["line_p"].append(p)
        if u_test.p_at(f0) < INPUT_LINE_P:
            continue
        amp = amp_test.amplitude_at(f0)
        params = {"freq_hz": f0, "amp": amp[0], "amp_ci95": list(amp[1])}
        out.append(Finding("periodic_disturbance", (name,), "multitaper_F", f_val, p, params))
    return _merge_lines(out)


def _undamped_pole_freqs(fitted) -> list[float]:
    """Frequencies (Hz) of the model's pole pairs damped less than :data:`UNDAMPED`."""
    _, f, xi, _ = fitted.fit.models[0].modal_parameters()
    return [float(v) for v, x in zip(f, xi, strict=True) if abs(x) < UNDAMPED and 0 < v < fitted.signals.fs / 2]


def _merge_lines(findings: list[Finding]) -> list[Finding]:
    """One finding per line frequency, listing every sensor it was found in."""
    merged: list[Finding] = []
    for f in sorted(findings, key=lambda x: x.p):
        same = [m for m in merged if abs(m.parameters["freq_hz"] - f.parameters["freq_hz"]) < LINE_MERGE_HZ]
        if same and f.p < 0.01:
            i = merged.index(same[0])
            merged[i] = Finding(
                same[0].effect,
                same[0].channels + f.channels,
                same[0].statistic,
                same[0].value,
                same[0].p,
                same[0].parameters,
            )
        elif not same:
            merged.append(f)
    return merged


def whiteness_findings(fitted, eps, mask, n_tests, table) -> list[Finding]:
    """Breusch-Godfrey: residual on the gradient columns and its own lags 1..L."""
    s = fitted.signals
    out = []
    for k, m in enumerate(fitted.fit.models):
        y = s.y[:, k] - fitted.disturbance()[:, k]
        psi = gradient_columns(m, y, s.inputs(fitted.spec), eps[:, k])
        z = np.column_stack([_lag(eps[:, k], i) for i in range(1, WHITENESS_LAGS + 1)])
        f, p = lm_f_test(eps[mask, k], psi[mask], z[mask])
        table["whiteness_p"].append(min(1.0, p * len(s.sensors)))
        p = min(1.0, p * n_tests)
        out.append(Finding("coloured_noise", (s.sensors[k],), "breusch_godfrey_F", f, p, {"lags": WHITENESS_LAGS}))
    return out


def whiteness_p(fitted: FittedModel) -> list[float]:
    """Breusch-Godfrey p-value per sensor (corrected for the sensors only)."""
    table: dict = {"whiteness_p": []}
    eps = fitted.one_step_errors()
    whiteness_findings(fitted, eps, usable(fitted.signals.n, fitted.spec), 1, table)
    return table["whiteness_p"]


def _window_modes(fitted: FittedModel, mask: np.ndarray):
    """Windowed re-identification at the model's orders: per window, the frequency and its
    standard deviation of the pole nearest each of the full fit's modes (NaN when none is
    within 15 %); the windows' input RMS; the windows' edges. Reuses the full fit as start."""
    from armaxmodal.diagnosis.model import fit_model
    from armaxmodal.modes.poles import SHARED, pole_rows

    def modes_of(fit):
        rows = [r for r in pole_rows(fit, SHARED) if 0 < r["damping"] < MAX_DAMPING]
        return np.array([[r["freq_hz"], r["freq_sd"]] for r in rows]).reshape(-1, 2)

    s = fitted.signals
    idx = np.flatnonzero(mask)
    edges = np.linspace(idx[0], idx[-1] + 1, N_WINDOWS + 1).astype(int)
    ref = modes_of(fitted.fit)
    freq = np.full((N_WINDOWS, len(ref)), np.nan)
    sd = np.full_like(freq, np.nan)
    for w in range(N_WINDOWS):
        fw = modes_of(fit_model(fitted.spec, s, (edges[w], edges[w + 1]), start=fitted).fit)
        for m, f0 in enumerate(ref[:, 0]):
            if fw.size:
                j = int(np.argmin(np.abs(fw[:, 0] - f0)))
                if abs(fw[j, 0] - f0) < 0.15 * f0:
                    freq[w, m], sd[w, m] = fw[j]
    rms = np.array([np.std(s.u[edges[w] : edges[w + 1]]) for w in range(N_WINDOWS)])
    return ref, freq, sd, rms, edges


def time_findings(fitted, mask, n_tests, table) -> list[Finding]:
    """Time variation: modes re-identified on consecutive windows; for each mode and each
    window boundary a Chow-type z of the means after against before (the windows' own
    standard deviations), corrected for modes x boundaries x tests. A shift that follows
    the windows' input RMS more closely than their order is amplitude dependence, left to
    the nonlinearity test; with a ride whose level rises in time the two are confounded and
    the parameters say so."""
    from armaxmodal.diagnosis.model import PiecewiseModel

    spec, s = fitted.spec, fitted.signals
    if isinstance(fitted, PiecewiseModel) or s.n < N_WINDOWS * 200:
        return []
    window = int(mask.sum()) // N_WINDOWS
    if not record_supports(window, spec.orders, 1 + len(spec.terms), len(s.sensors), True):
        table["time_varying_not_run"] = (
            f"{N_WINDOWS} windows of {window} samples cannot hold the model's orders "
            f"{spec.orders}: the record is too short for this test"
        )
        return []
    ref, freq, sd, rms, edges = _window_modes(fitted, mask)
    best = (0.0, None, None)
    for m in range(ref.shape[0]):
        ok = np.isfinite(freq[:, m]) & np.isfinite(sd[:, m]) & (sd[:, m] > 0)
        if ok.sum() < N_WINDOWS:
            continue
        for b in range(2, N_WINDOWS - 1):  # at least two windows each side
            f_b, f_a = freq[:b, m], freq[b:, m]
            var = np.sum(sd[:b, m] ** 2) / b**2 + np.sum(sd[b:, m] ** 2) / (N_WINDOWS - b) ** 2
            z = abs(f_a.mean() - f_b.mean()) / np.sqrt(var)
            if z > best[0]:
                best = (z, m, b)
    z, m, b = best
    if m is None:
        return []
    n_checks = ref.shape[0] * (N_WINDOWS - 3)
    p = min(1.0, 2 * stats.norm.sf(z) * n_checks * n_tests)
    table["time_varying_p"] = p
    order = np.arange(N_WINDOWS)
    r_time = abs(np.corrcoef(order, freq[:, m])[0, 1])
    r_amp = abs(np.corrcoef(rms, freq[:, m])[0, 1]) if np.std(rms) > 0 else 0.0
    confounded = abs(np.corrcoef(order, rms)[0, 1]) > 0.8 if np.std(rms) > 0 else False
    if r_amp > r_time and not confounded:
        return []
    params = {
        "change_time_s": float(edges[b] / s.fs),
        "mode_hz": float(ref[m, 0]),
        "freq_before_hz": float(np.mean(freq[:b, m])),
        "freq_after_hz": float(np.mean(freq[b:, m])),
        "window_freqs_hz": freq[:, m].tolist(),
        "window_input_rms": rms.tolist(),
        "confounded_with_amplitude": bool(confounded),
    }
    return [Finding("time_varying", tuple(s.sensors), "chow_z", z, p, params, payload=int(edges[b]))]


def second_input_findings(fitted, eps, mask, n_tests, table) -> list[Finding]:
    """A recorded channel that is an input, not a response: the base explains little of it
    (coherence below ``SECOND_INPUT_COHERENCE``, :func:`~armaxmodal.prepare.quality.input_coherence`)
    and, entering the other channels through the dynamics as a second input ``B_2 / A``, it
    explains their one-step residual: the score test of its lags ``nk .. nk+nb-1`` filtered by
    ``1/C`` (the gradient in ``B_2``), with a constant among the regressors so an offset is not
    read as an input. Only outputs the base drives (coherent) are tested. p per explained
    channel, Bonferroni over candidates x sensors x tests."""
    s = fitted.signals
    k_count = len(s.sensors)
    y = s.y - fitted.disturbance()
    lo, hi = np.flatnonzero(mask)[[0, -1]]
    coherence = input_coherence(s.u[lo : hi + 1], y[lo : hi + 1], s.fs)
    table["base_coherence"] = coherence.tolist()
    candidates = [c for c in range(k_count) if coherence[c] < SECOND_INPUT_COHERENCE] if k_count > 1 else []
    _, nb, _, nk = fitted.fit.orders
    u = s.inputs(fitted.spec)
    psi = {}
    out = []
    for c in candidates:
        f_sum, ps = 0.0, {}
        # outputs the base drives: where no channel is a response, nothing tells an input
        for k in (k for k in range(k_count) if coherence[k] >= SECOND_INPUT_COHERENCE):
            m = fitted.fit.models[k]
            if k not in psi:
                grad = gradient_columns(m, y[:, k], u, eps[:, k])[mask]
                psi[k] = np.column_stack([np.ones(grad.shape[0]), grad])
            z = lfilter([1.0], m.c, y[:, c] - y[mask, c].mean())
            f, p = lm_f_test(eps[mask, k], psi[k], np.column_stack([_lag(z, nk + j) for j in range(nb)])[mask])
            f_sum += f
            ps[s.sensors[k]] = min(1.0, p * k_count * n_tests)
        explains = [name for name, p in sorted(ps.items(), key=lambda kv: kv[1]) if p < 0.01]
        if explains:
            params = {"base_coherence": float(coherence[c]), "explains": explains, "p_per_channel": ps}
            out.append(Finding("second_input", (s.sensors[c],), "score_F", f_sum, min(ps.values()), params))
    return out
