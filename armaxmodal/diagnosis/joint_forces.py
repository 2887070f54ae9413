"""The joint-force test: is the residual a nonlinear force in a joint, and which kind?

Candidate forces are built from the model's simulated response -- a function of a deflection (a
stiffness nonlinearity: cubic, quadratic, ``|d| d``) or of a relative velocity (a damping
nonlinearity: dry friction, quadratic damping) of each sensor to the base and of each pair --
and enter through the structure's dynamics as a second input ``B_nl / A``. The score test's
gradient in ``B_nl`` is the candidate filtered by ``1 / C``. One test for both kinds: the
candidate the residual follows best names the effect and its joint (a deflection and a velocity
are a quarter period apart at every frequency, so the two are told apart by phase).
"""

from __future__ import annotations

import numpy as np
from scipy.signal import lfilter

from armaxmodal.diagnosis.evidence import gradient_columns, projected_f
from armaxmodal.diagnosis.finding import Finding
from armaxmodal.diagnosis.model import FittedModel
from armaxmodal.diagnosis.model import lagged as _lag
from armaxmodal.recording import Recording
from armaxmodal.stats import MAX_DAMPING

__all__ = ["JOINT_TERMS", "TERM_WORDS", "deflections", "joint_force_findings"]

#: candidate joint forces: ``kind -> (effect, motion, force of that motion)``. A stiffness
#: nonlinearity is a function of a deflection, a damping nonlinearity of a relative velocity
#: (dry friction in a joint, quadratic damping); the two are told apart by which candidate
#: the residual follows (a quarter period apart at every frequency)
JOINT_TERMS = {
    "cubic": ("stiffness_nonlinearity", "deflection", lambda d: d**3),
    "quadratic": ("stiffness_nonlinearity", "deflection", lambda d: d**2),
    "abs_times": ("stiffness_nonlinearity", "deflection", lambda d: np.abs(d) * d),
    "dry_friction": ("damping_nonlinearity", "velocity", np.sign),
    "quadratic_damping": ("damping_nonlinearity", "velocity", lambda v: np.abs(v) * v),
}


#: each term as a person reads it (the verdict's words)
TERM_WORDS = {
    "cubic": "a cubic spring",
    "quadratic": "a quadratic spring",
    "abs_times": "a |d| d spring",
    "dry_friction": "dry friction",
    "quadratic_damping": "quadratic damping",
}


def deflections(fitted: FittedModel, integrations: int = 2) -> dict[tuple[str, str], np.ndarray]:
    """Deflections of the model's simulated response (``integrations=1``: relative velocities):
    each sensor relative to the base and each pair of sensors, (n,) each, keyed by (sensor,
    other or input). They come from the simulated relative accelerations integrated in the
    frequency domain, from half the lowest mode (and the input's excited band) up."""
    from armaxmodal.spectra import excited_band

    s = fitted.signals
    rel = fitted.simulated() - s.u[:, None]
    # below the first mode the relative motion is quasi-static and an integral only
    # amplifies the model's low-frequency error: integrate from half the lowest mode up
    _, f_modes, xi, _ = fitted.fit.models[0].modal_parameters()
    physical = f_modes[(xi > 0) & (xi < MAX_DAMPING)]
    f_first = float(physical.min()) if physical.size else 0.0
    f_lo = max(excited_band(Recording(s.fs, s.u, s.y, s.sensors, s.input_name))[0], 0.5 * f_first, 3 * s.fs / s.n)
    f = np.fft.rfftfreq(s.n, 1 / s.fs)
    spec = np.fft.rfft(rel, axis=0)
    gain = np.zeros(f.size, complex)
    gain[f >= f_lo] = 1.0 / (2j * np.pi * f[f >= f_lo]) ** integrations
    disp = np.fft.irfft(spec * gain[:, None], s.n, axis=0)
    out = {(name, s.input_name): disp[:, k] for k, name in enumerate(s.sensors)}
    for k in range(len(s.sensors)):
        for j in range(k + 1, len(s.sensors)):
            out[(s.sensors[k], s.sensors[j])] = disp[:, k] - disp[:, j]
    return out


def joint_force_findings(fitted, eps, mask, n_tests, table) -> list[Finding]:
    """Score test of candidate joint forces built from the simulated response
    (:data:`JOINT_TERMS` of every deflection and relative velocity), entering through the
    structure's dynamics as a second input ``B_nl / A``: the one-step error's gradient in
    ``B_nl`` is the term filtered by 1/C (lags 0..TERM_LAGS-1 tested). The candidate with the
    largest summed F over sensors is tested, and names the effect (stiffness or damping); p
    corrected for candidates x sensors x tests."""
    from armaxmodal.diagnosis.model import TERM_LAGS

    s = fitted.signals
    motion = {"deflection": deflections(fitted, 2), "velocity": deflections(fitted, 1)}
    candidates = [(kind, pair) for kind in JOINT_TERMS for pair in motion[JOINT_TERMS[kind][1]]]
    # the score test against each candidate shares the gradient columns: project them out once
    bases, resid = [], []
    dist = fitted.disturbance()
    for k, m in enumerate(fitted.fit.models):
        q, _ = np.linalg.qr(gradient_columns(m, s.y[:, k] - dist[:, k], s.inputs(fitted.spec), eps[:, k])[mask])
        bases.append(q)
        resid.append(eps[mask, k] - q @ (q.T @ eps[mask, k]))
    best, best_sum, best_ps, places = None, -np.inf, None, {}
    for kind, pair in candidates:
        effect, quantity, force = JOINT_TERMS[kind]
        term = force(motion[quantity][pair])
        term = term / max(float(np.std(term)), 1e-300)
        fs_, ps = [], []
        for k, m in enumerate(fitted.fit.models):
            z = lfilter([1.0], m.c, term)
            cols = np.column_stack([_lag(z, j) for j in range(TERM_LAGS)])[mask]
            f, p = projected_f(resid[k], cols - bases[k] @ (bases[k].T @ cols), bases[k].shape[1])
            fs_.append(f)
            ps.append(p)
        place = "-".join(pair)
        places[place] = max(places.get(place, 0.0), float(sum(fs_)))
        if sum(fs_) > best_sum:
            best, best_sum, best_ps = (kind, pair, term), sum(fs_), ps
    if best is None:
        return []
    kind, pair, term = best
    scale = len(candidates) * n_tests
    ps = [min(1.0, p * scale) for p in best_ps]
    table["nonlinear_p"] = ps
    channels = tuple(name for name, p in zip(s.sensors, ps, strict=True) if p < 0.01)
    if not channels:
        return []
    params = {"term": kind, "between": list(pair), **_place_evidence(places)}
    return [Finding(JOINT_TERMS[kind][0], channels, "score_F", best_sum, min(ps), params, payload=term)]


def _place_evidence(places: dict[str, float]) -> dict:
    """How sure the test is of the joint: the summed score F of the best term at every candidate
    place (``place_score_F``, largest first), and the runner-up place with the ratio of the chosen
    place's F to its (``place_margin``; near 1: the record cannot tell the two joints apart; None
    where there is one place)."""
    ranked = sorted(places.items(), key=lambda item: -item[1])
    second, f2 = ranked[1] if len(ranked) > 1 else (None, 0.0)
    margin = ranked[0][1] / f2 if f2 > 0 else None  # one place (a single sensor): nothing to tell apart
    return {"place_score_F": dict(ranked), "runner_up_place": second, "place_margin": margin}
