"""Each effect's fix -- the model spec with that effect added (``add_*``) -- and what the refit
says about it (``*_parameters``). The registry (:mod:`.effects`) pairs them with their effect."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.optimize import minimize_scalar

from armaxmodal.diagnosis.clock_drift import remaining_drift
from armaxmodal.diagnosis.finding import Finding
from armaxmodal.diagnosis.gain_change import remaining_gain
from armaxmodal.diagnosis.level_shift import remaining_step
from armaxmodal.diagnosis.model import FittedModel, ModelSpec, response_free_of, usable
from armaxmodal.stats import MAX_DAMPING, Z95

__all__ = [
    "add_clipped",
    "add_clock_drift",
    "add_delay",
    "add_fault",
    "add_joint_force",
    "add_line",
    "add_mode",
    "add_noise_model",
    "add_second_input",
    "add_trend",
    "clock_drift_parameters",
    "finding_parameters",
    "joint_force_parameters",
    "line_parameters",
    "mode_parameters",
    "noise_model_parameters",
    "refine_line",
    "second_input_parameters",
    "time_change_parameters",
    "trend_parameters",
]

#: C coefficients a richer noise model adds.
EXTRA_NC_STEP = 6


def add_delay(spec: ModelSpec, finding: Finding, fitted: FittedModel) -> ModelSpec:
    """The channel moved: an input late by d is moved earlier by d; a sensor late by d likewise."""
    shifts = dict(spec.shifts)
    name = finding.channels[0]
    shifts[name] = shifts.get(name, 0.0) + finding.parameters["delay_samples"]
    return replace(spec, shifts=tuple(sorted(shifts.items())))


def add_trend(spec: ModelSpec, finding: Finding, fitted: FittedModel) -> ModelSpec:
    """One more polynomial degree of the output's trend (at most a quadratic)."""
    return replace(spec, trend_degree=min(2, max(1, spec.trend_degree + 1)))


def add_level_shift(spec: ModelSpec, finding: Finding, fitted: FittedModel) -> ModelSpec:
    """The step taken out of the channel from its sample on (the size the test measured; added to
    a step already taken out there)."""
    at, size = (finding.channels[0], int(finding.parameters["sample"])), float(finding.parameters["size"])
    others = tuple(step for step in spec.steps if step[:2] != at)
    return replace(spec, steps=others + ((*at, size + sum(v for c, t, v in spec.steps if (c, t) == at)),))


def add_gain_change(spec: ModelSpec, finding: Finding, fitted: FittedModel) -> ModelSpec:
    """The gain change taken out of the channel from its sample on (combined with one already there)."""
    at, factor = (finding.channels[0], int(finding.parameters["sample"])), float(finding.parameters["factor"])
    before = np.prod([v for c, t, v in spec.gains if (c, t) == at])
    return replace(spec, gains=tuple(g for g in spec.gains if g[:2] != at) + ((*at, factor * before),))


def add_clock_drift(spec: ModelSpec, finding: Finding, fitted: FittedModel) -> ModelSpec:
    """The channel resampled on its own clock (added to a drift already taken out of it)."""
    drifts = dict(spec.drifts)
    name = finding.channels[0]
    drifts[name] = drifts.get(name, 0.0) + 1e-6 * float(finding.parameters["rate_ppm"])
    return replace(spec, drifts=tuple(sorted(drifts.items())))


def add_line(spec: ModelSpec, finding: Finding, fitted: FittedModel) -> ModelSpec:
    """A sine at the line's frequency, refined (:func:`refine_line`)."""
    f0 = refine_line(fitted, finding.parameters["freq_hz"], finding.channels)
    return replace(spec, lines_hz=spec.lines_hz + (f0,))


def add_noise_model(spec: ModelSpec, finding: Finding, fitted: FittedModel) -> ModelSpec:
    """A richer noise model: :data:`EXTRA_NC_STEP` more C coefficients."""
    return replace(spec, extra_nc=spec.extra_nc + EXTRA_NC_STEP)


def add_mode(spec: ModelSpec, finding: Finding, fitted: FittedModel) -> ModelSpec:
    """One more pole pair; nb and nc follow na's rules."""
    na, nb, nc, nk = spec.orders
    return replace(spec, orders=(na + 2, nb + 2, nc + 2, nk))


def add_clipped(spec: ModelSpec, finding: Finding, fitted: FittedModel) -> ModelSpec:
    """The clipped channels' samples at the rail filled from the model."""
    return replace(spec, clipped=tuple(sorted(set(spec.clipped) | set(finding.channels))))


def add_fault(spec: ModelSpec, finding: Finding, fitted: FittedModel) -> ModelSpec:
    """The spoiled samples (the finding's payload) filled from the model."""
    return replace(spec, faults=spec.faults + ((finding.channels[0], tuple(finding.payload)),))


def add_second_input(spec: ModelSpec, finding: Finding, fitted: FittedModel) -> ModelSpec:
    """The channel taken from the outputs and made an input."""
    name = finding.channels[0]
    return replace(spec, terms=spec.terms + (name,), inputs_from=spec.inputs_from + (name,))


def add_joint_force(spec: ModelSpec, finding: Finding, fitted: FittedModel) -> ModelSpec:
    """The joint force (the finding's payload, built from the model's simulated response) as an
    extra input."""
    name = f"{finding.parameters['term']}:{'-'.join(finding.parameters['between'])}#{len(spec.terms) + 1}"
    fitted.signals.extra[name] = finding.payload
    return replace(spec, terms=spec.terms + (name,))


def refine_line(fitted: FittedModel, freq_hz: float, channels) -> float:
    """The line's frequency to a small fraction of the record's resolution: the maximum of
    the periodogram (least squares for one sine) of the channels' residual from a response
    model that cannot carry the line (:func:`~.model.response_free_of`), summed over channels."""
    s = fitted.signals
    mask = usable(s.n, fitted.spec)
    t = np.flatnonzero(mask) / s.fs
    trial = replace(fitted.spec, lines_hz=fitted.spec.lines_hz + (freq_hz,))
    idx = [s.sensors.index(c) for c in channels]
    y = s.y - fitted.disturbance()
    r = (y - response_free_of(trial, fitted.fit, s.u, y))[mask][:, idx]

    def power(f):
        e = np.exp(-2j * np.pi * f * t)
        return -float(np.sum(np.abs(e @ r) ** 2))

    df = s.fs / s.n
    grid = freq_hz + np.linspace(-df, df, 81)
    best = grid[int(np.argmin([power(f) for f in grid]))]
    step = grid[1] - grid[0]
    res = minimize_scalar(power, bounds=(best - step, best + step), method="bounded", options={"xatol": 1e-4 * step})
    return float(res.x)


def finding_parameters(finding: Finding, fitted) -> dict:
    """The finding's own parameters: an effect whose fit adds nothing to them."""
    return dict(finding.parameters)


def time_change_parameters(finding: Finding, fitted) -> dict:
    """The change's time and each mode before and after it."""
    return {**finding.parameters, "modes_each_side": _modes_each_side(fitted)}


def level_shift_parameters(finding: Finding, fitted) -> dict:
    """The step's time (s, with the test's 95 % interval) and its size as the refit completed it (the
    channel's units, with a 95 % interval from what remains in the refitted model's residual)."""
    name, first = finding.channels[0], int(finding.parameters["sample"])
    (size,) = [v for c, t, v in fitted.spec.steps if (c, t) == (name, first)]
    left, sd = remaining_step(fitted, name, first)
    size += left
    return {
        **finding.parameters,
        "size_first": finding.parameters["size"],
        "size": size,
        "size_ci95": [size - Z95 * sd, size + Z95 * sd],
    }


def gain_change_parameters(finding: Finding, fitted) -> dict:
    """The change's time (s, with the test's 95 % interval) and its factor as the refit completed it,
    with a 95 % interval from what remains in the refitted model's residual."""
    name, first = finding.channels[0], int(finding.parameters["sample"])
    (factor,) = [v for c, t, v in fitted.spec.gains if (c, t) == (name, first)]
    left, sd = remaining_gain(fitted, name, first)
    factor *= 1 + left
    sd /= seen_share(finding.parameters["factor"] - 1, factor - 1)
    return {
        **finding.parameters,
        "factor_first": finding.parameters["factor"],
        "factor": factor,
        "factor_ci95": [factor * (1 - Z95 * sd), factor * (1 + Z95 * sd)],
    }


def seen_share(first: float, total: float) -> float:
    """The share of a change the residual shows: its first reading over the total the refits
    completed (a model fitted with the change in the data carries the rest: 0.054 of a planted
    gain change of 0.1). The residual's SD of what remains is the SD of the total over that share;
    read as the total's, the factor's interval held 1.1 in 13 of 20 rides. 1 where the first
    reading is not a part of the total (a drift's first-order reading overshoots)."""
    share = first / total if total else 1.0
    return share if 0 < share < 1 else 1.0


def clock_drift_parameters(finding: Finding, fitted) -> dict:
    """The drift's rate (ppm: microseconds a second) as the refit completed it, with a 95 % interval
    from what remains in the refitted model's residual, and the delay it adds over the record (ms)."""
    name, s = finding.channels[0], fitted.signals
    left, sd = remaining_drift(fitted, name)
    rate = dict(fitted.spec.drifts)[name] + left
    return {
        **finding.parameters,
        "rate_first_ppm": finding.parameters["rate_ppm"],
        "rate_ppm": 1e6 * rate,
        "rate_ci95_ppm": [1e6 * (rate - Z95 * sd), 1e6 * (rate + Z95 * sd)],
        "delay_change_ms": 1e3 * rate * s.n / s.fs,
    }


def trend_parameters(finding: Finding, fitted) -> dict:
    """Each channel's offset (mid-record) and drift per second, with 95 % intervals."""
    spec, s = fitted.spec, fitted.signals
    dur = s.n / s.fs
    out = {}
    for name in finding.channels:
        k = s.sensors.index(name)
        th, cov = fitted.theta[:, k], fitted.theta_cov[k]
        sd = np.sqrt(np.clip(np.diag(cov), 0, None))
        # tau runs -1..1 over the record: the offset is the value mid-record, drift per s
        out[name] = {
            "offset": float(th[0]),
            "offset_ci95": [float(th[0] - Z95 * sd[0]), float(th[0] + Z95 * sd[0])],
            "drift_per_s": float(th[1] * 2 / dur),
            "drift_ci95_per_s": [float((th[1] - Z95 * sd[1]) * 2 / dur), float((th[1] + Z95 * sd[1]) * 2 / dur)],
        }
    return {"trend_degree": spec.trend_degree, "per_channel": out}


def line_parameters(finding: Finding, fitted) -> dict:
    """The line's frequency and each channel's amplitude, with 95 % intervals."""
    spec, s = fitted.spec, fitted.signals
    i0 = spec.trend_degree + 1 + 2 * (len(spec.lines_hz) - 1)
    amps = {}
    for name in finding.channels:
        k = s.sensors.index(name)
        a, b = fitted.theta[i0 : i0 + 2, k]
        cov = fitted.theta_cov[k][i0 : i0 + 2, i0 : i0 + 2]
        amp = float(np.hypot(a, b))
        grad = np.array([a, b]) / max(amp, 1e-300)
        sd = float(np.sqrt(max(grad @ cov @ grad, 0.0)))
        amps[name] = {"amp": amp, "amp_ci95": [amp - Z95 * sd, amp + Z95 * sd]}
    first = amps[finding.channels[0]]
    return {"freq_hz": spec.lines_hz[-1], "amp": first["amp"], "amp_ci95": first["amp_ci95"], "per_channel": amps}


def joint_force_parameters(finding: Finding, fitted) -> dict:
    """The term, its joint, and its share of each channel: the RMS of its simulated contribution
    over the output's."""
    spec, s = fitted.spec, fitted.signals
    u = np.zeros((s.n, 1 + len(spec.terms)))
    u[:, -1] = s.extra[spec.terms[-1]]
    share = {
        name: float(np.std(fitted.fit.models[k].simulate(u)) / np.std(s.y[:, k]))
        for k, name in enumerate(s.sensors)
        if name in finding.channels
    }
    return {**finding.parameters, "rms_share_of_output": share}


def second_input_parameters(finding: Finding, fitted) -> dict:
    """Each explained channel's share of the response to the new input."""
    spec, s = fitted.spec, fitted.signals
    u = np.zeros((s.n, 1 + len(spec.terms)))
    u[:, 1 + spec.terms.index(finding.channels[0])] = s.extra[finding.channels[0]]
    share = {
        name: float(np.std(fitted.fit.models[k].simulate(u)) / np.std(s.y[:, k]))
        for k, name in enumerate(s.sensors)
        if name in finding.parameters["explains"]
    }
    return {**finding.parameters, "rms_share_of_output": share}


def mode_parameters(finding: Finding, fitted) -> dict:
    """The order reached and the modes the added pole pair gave."""
    from armaxmodal.diagnosis.missing_mode import added_modes

    return {**finding.parameters, "na": fitted.spec.orders[0], "added_modes": added_modes(finding.payload, fitted)}


def noise_model_parameters(finding: Finding, fitted) -> dict:
    """The noise model's order before and after."""
    spec = fitted.spec
    return {"nc": spec.orders[2] + spec.extra_nc, "nc_before": spec.orders[2] + spec.extra_nc - EXTRA_NC_STEP}


def _modes_each_side(piecewise) -> list[dict]:
    """Each mode of the fit before the change with its nearest match after it."""
    from armaxmodal.modes.poles import SHARED, pole_rows

    def modes(fit):
        return [r for r in pole_rows(fit, SHARED) if 0 < r["damping"] < MAX_DAMPING]

    after = modes(piecewise.after.fit)
    out = []
    for r in sorted(modes(piecewise.before.fit), key=lambda r: r["freq_hz"]):
        if not after:
            break
        a = min(after, key=lambda x: abs(x["freq_hz"] - r["freq_hz"]))
        out.append(
            {
                "freq_before_hz": float(r["freq_hz"]),
                "freq_after_hz": float(a["freq_hz"]),
                "damping_before": float(r["damping"]),
                "damping_after": float(a["damping"]),
            }
        )
    return out
