"""A clock that drifts: a channel's recorder keeps its own clock, a little off the others', so its
delay grows linearly through the record (recorders that are not synchronised; IMUs each on their
own crystal, 10-100 ppm apart).

A sensor recorded as ``y(t - delta(t))``, ``delta(t) = delta_0 + r (t - c)`` about the record's
middle ``c``, leaves the one-step residual ``-(delta(t) - delta_0) dz/dt`` to first order, ``z`` the
output's predicted part through the predictor's filter (``(B / C) u``, the gain change's regressor,
:mod:`.gain_change`). The constant part is a delay the B taps or the delay test take; the rate is the
least-squares coefficient of ``(t - c) dz/dt`` with ``dz/dt`` itself as a nuisance regressor, so a
constant delay reads no rate. It is judged as the gain change is: over its Newey-West spread, never
below the white-noise one; one test per sensor (no time is searched).

Every output drifting alike is the input's clock (one finding on the input, the rate the input's:
the outputs' with its sign changed), as every output late alike is the input's delay
(:mod:`.delays`). Outputs that drift unalike are a change of the structure, which the dynamics
moves in each sensor by its own amount (springs 12 % stiffer half way read -3 to -11 ppm on the
supine ride's four sensors): nothing is named, and the time-change test takes it.
"""

from __future__ import annotations

import numpy as np
from scipy.special import ndtr

from armaxmodal.diagnosis.delays import SPREAD_ALPHA, pooled
from armaxmodal.diagnosis.finding import Finding
from armaxmodal.diagnosis.gain_change import SHARED_Z, predicted_part
from armaxmodal.diagnosis.level_shift import newey_west_sum
from armaxmodal.stats import Z95

__all__ = ["drift_findings", "drift_rate", "remaining_drift"]


def _derivative(x: np.ndarray) -> np.ndarray:
    """``dx/dt`` in units per sample: the Fourier derivative of the mirrored record (exact for
    band-limited data; a central difference reads a 0.4 x fs component 24 % low)."""
    n = x.size
    ext = np.concatenate([x, x[::-1]])
    f = np.fft.rfftfreq(ext.size)
    return np.fft.irfft(np.fft.rfft(ext) * 2j * np.pi * f, ext.size)[:n]


def drift_rate(eps: np.ndarray, z: np.ndarray, mask: np.ndarray, sigma: float) -> tuple[float, float]:
    """``(r, sd)``: the rate (samples per sample) at which a channel's delay grows, from its one-step
    residual ``eps`` and its filtered predicted part ``z`` (n,), counted where ``mask``, with the SD
    from the Newey-West spread, never below the white-noise one (``sigma``, the residual's SD)."""
    e = np.where(mask, eps, 0.0)
    slope = np.where(mask, _derivative(z), 0.0)
    ramp = (np.arange(z.size) - (z.size - 1) / 2) * slope
    x = ramp - slope * (slope @ ramp) / max(slope @ slope, 1e-300)  # the constant delay partialled out
    energy = max(float(x @ x), 1e-300)
    coef = float(x @ e) / energy
    delay = float(slope @ (e - coef * ramp)) / max(slope @ slope, 1e-300)
    spread = max(np.sqrt(newey_west_sum(x * (e - coef * ramp - delay * slope))), sigma * np.sqrt(energy))
    return -coef, float(spread / energy)  # the residual is -(delta - delta_0) dz/dt


def _rates(fitted, mask: np.ndarray) -> list[tuple[float, float]]:
    """Each output's ``(r, sd)`` under ``fitted``."""
    out = []
    for k in range(len(fitted.signals.sensors)):
        z, e, sigma = predicted_part(fitted, k, mask)
        out.append(drift_rate(e, z, mask, sigma))
    return out


def _common(rates: list[tuple[float, float]]) -> tuple[float, float, float]:
    """``(r, sd, spread_p)``: the outputs' rates pooled as the delays are (:func:`.delays.pooled`)."""
    mean, sd, _, spread_p = pooled(*np.array(rates).T)
    return mean, sd, spread_p


def remaining_drift(fitted, name: str) -> tuple[float, float]:
    """``(r, sd)``: the drift still in channel ``name`` under ``fitted``, as the channel's own rate
    (on the input: the outputs' common rate with its sign changed)."""
    from armaxmodal.diagnosis.model import counted

    rates = _rates(fitted, counted(fitted))
    if name == fitted.signals.input_name:
        mean, sd, _ = _common(rates)
        return -mean, sd
    return rates[fitted.signals.sensors.index(name)]


def _finding(channel: str, rate: float, sd: float, p: float, s, extra: dict | None = None) -> Finding:
    """A ``clock_drift`` finding: the rate in ppm with its interval, and the delay it adds over the
    record."""
    half = Z95 * sd
    params = {
        "rate_ppm": 1e6 * rate,
        "rate_ci95_ppm": [1e6 * (rate - half), 1e6 * (rate + half)],
        "delay_change_ms": 1e3 * rate * s.n / s.fs,
        **(extra or {}),
    }
    return Finding("clock_drift", (channel,), "drift_z", abs(rate) / sd, p, params)


def drift_findings(fitted, mask: np.ndarray, n_tests: int, table: dict) -> list[Finding]:
    """``clock_drift`` findings: each output that alone shows a drift, or the input when every output
    drifts alike; ``table["drift_p"]`` gets every output's corrected p."""
    s = fitted.signals
    rates = _rates(fitted, mask)
    table["drift_p"] = [min(1.0, 2 * float(ndtr(-abs(r) / sd)) * n_tests) for r, sd in rates]
    showing = [k for k, (r, sd) in enumerate(rates) if abs(r) > SHARED_Z * sd]
    if len(showing) > 1:
        mean, sd, spread_p = _common([rates[k] for k in showing])
        if spread_p < SPREAD_ALPHA:
            return []  # each sensor by its own amount: the structure changed, not a clock
        if len(showing) == len(s.sensors):
            p = max(table["drift_p"])
            per_output = {s.sensors[k]: 1e6 * rates[k][0] for k in showing}
            return [_finding(s.input_name, -mean, sd, p, s, {"per_output_rate_ppm": per_output, "spread_p": spread_p})]
    return [_finding(s.sensors[k], *rates[k], table["drift_p"][k], s) for k in showing]
