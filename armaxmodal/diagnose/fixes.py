"""Each effect's fix: the model spec with that effect added, and what the fit says about it."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.optimize import minimize_scalar

from .evidence import LINE_MERGE_HZ, Finding, _undamped_pole_freqs
from .model import FittedModel, ModelSpec, usable

__all__ = ["add_effect", "effect_parameters"]

#: C coefficients a richer noise model adds.
EXTRA_NC_STEP = 6


def add_effect(spec: ModelSpec, finding: Finding, fitted: FittedModel) -> ModelSpec:
    """``spec`` with the effect of ``finding`` added (see :mod:`armaxmodal.diagnose.model`)."""
    if finding.effect == "input_delay":
        shifts = dict(spec.shifts)
        name = finding.channels[0]
        lead = finding.parameters["delay_samples"]
        # an input late by d is moved earlier by d; a sensor late by d likewise
        shifts[name] = shifts.get(name, 0.0) + lead
        return replace(spec, shifts=tuple(sorted(shifts.items())))
    if finding.effect == "offset_drift":
        return replace(spec, trend_degree=min(2, max(1, spec.trend_degree + 1)))
    if finding.effect == "periodic_disturbance":
        f0 = refine_line(fitted, finding.parameters["freq_hz"])
        # a pole pair that had absorbed the line goes: the sinusoid now carries it
        absorbed = [f for f in _undamped_pole_freqs(fitted) if abs(f - f0) < LINE_MERGE_HZ]
        na, nb, nc, nk = spec.orders
        orders = (max(2, na - 2 * len(absorbed)), nb, nc, nk)
        return replace(spec, orders=orders, lines_hz=spec.lines_hz + (f0,))
    if finding.effect == "coloured_noise":
        return replace(spec, extra_nc=spec.extra_nc + EXTRA_NC_STEP)
    raise ValueError(f"no fix for effect {finding.effect!r}")


def refine_line(fitted: FittedModel, freq_hz: float) -> float:
    """The line's frequency to a small fraction of the record's resolution: the maximum of
    the simulation residual's periodogram summed over sensors (least squares for one sine)."""
    s = fitted.signals
    mask = usable(s.n, fitted.spec)
    r = fitted.simulation_errors()[mask]
    t = np.flatnonzero(mask) / s.fs

    def power(f):
        e = np.exp(-2j * np.pi * f * t)
        return -float(np.sum(np.abs(e @ r) ** 2))

    df = s.fs / s.n
    res = minimize_scalar(power, bounds=(freq_hz - df, freq_hz + df), method="bounded", options={"xatol": 1e-6 * df})
    return float(res.x)


def effect_parameters(finding: Finding, fitted: FittedModel) -> dict:
    """The effect's parameters in the refitted model, with 95 % intervals where the fit gives them."""
    spec, s = fitted.spec, fitted.signals
    if finding.effect == "offset_drift":
        dur = s.n / s.fs
        out = {}
        for name in finding.channels:
            k = s.sensors.index(name)
            th, cov = fitted.theta[:, k], fitted.theta_cov[k]
            sd = np.sqrt(np.clip(np.diag(cov), 0, None))
            # tau runs -1..1 over the record: the offset is the value mid-record, drift per s
            out[name] = {
                "offset": float(th[0]),
                "offset_ci95": [float(th[0] - 1.96 * sd[0]), float(th[0] + 1.96 * sd[0])],
                "drift_per_s": float(th[1] * 2 / dur),
                "drift_ci95_per_s": [float((th[1] - 1.96 * sd[1]) * 2 / dur), float((th[1] + 1.96 * sd[1]) * 2 / dur)],
            }
        return {"trend_degree": spec.trend_degree, "per_channel": out}
    if finding.effect == "periodic_disturbance":
        i0 = spec.trend_degree + 1 + 2 * (len(spec.lines_hz) - 1)
        amps = {}
        for name in finding.channels:
            k = s.sensors.index(name)
            a, b = fitted.theta[i0 : i0 + 2, k]
            cov = fitted.theta_cov[k][i0 : i0 + 2, i0 : i0 + 2]
            amp = float(np.hypot(a, b))
            grad = np.array([a, b]) / max(amp, 1e-300)
            sd = float(np.sqrt(max(grad @ cov @ grad, 0.0)))
            amps[name] = {"amp": amp, "amp_ci95": [amp - 1.96 * sd, amp + 1.96 * sd]}
        first = amps[finding.channels[0]]
        return {"freq_hz": spec.lines_hz[-1], "amp": first["amp"], "amp_ci95": first["amp_ci95"], "per_channel": amps}
    if finding.effect == "coloured_noise":
        return {"nc": spec.orders[2] + spec.extra_nc, "nc_before": spec.orders[2] + spec.extra_nc - EXTRA_NC_STEP}
    return dict(finding.parameters)
