"""The acceptance rule: refit with an effect, judge the fix on held-out data, keep it or say why not.

A fix is kept when the held-out error of the outputs it concerns falls significantly (one-sided
Diebold-Mariano on the squared one-step or simulation error) and BIC falls; an effect's own rule
may replace that (``effects.REGISTRY``): a fact of the record (a clipped or stuck run) need
only not hurt, and a delay within B's reach need only be no worse.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy import stats

from armaxmodal.diagnosis.clock_drift import remaining_drift
from armaxmodal.diagnosis.finding import Finding
from armaxmodal.diagnosis.gain_change import remaining_gain
from armaxmodal.diagnosis.level_shift import remaining_step
from armaxmodal.diagnosis.model import (
    HeldOut,
    ModelSpec,
    Signals,
    fit_model,
    fit_piecewise,
    held_out,
    held_out_piecewise,
    model_bic,
    usable,
    widened_start,
)
from armaxmodal.diagnosis.result import Effect, Stage

__all__ = [
    "Judgement",
    "NK_REACH",
    "NO_WORSE",
    "STEP_PASSES",
    "delay_kept",
    "fact_kept",
    "fault_kept",
    "refit_clock_drift",
    "refit_gain_change",
    "refit_level_shift",
    "refit_moved",
    "refit_piecewise",
    "refit_spec",
    "significant_drop",
    "try_fix",
]

#: A fix that must only not hurt (a delay the B taps absorbed, a clipped or stuck run filled)
#: may raise the held-out error by this fraction: the refit's own scatter.
NO_WORSE = 0.01
#: nk candidates either side of where a delay's move puts the baseline's (and the baseline's).
NK_REACH = 1
#: refits at most that complete a level shift's size, a gain change's factor or a clock's drift, each
#: while what remains exceeds its SD (a 0.8 step on the supine ride's pelvis: 0.791 at first, and a
#: second 0.009 step found the next round; a gain of 1.2 read 1.073 at first and 1.190 after three
#: passes; a drift of 278 ppm read 322 at first, its first-order pattern outgrown by a sample's drift)
STEP_PASSES = 8
#: what may remain of a change, in its SD, when the refits stop: the residual shows only part of
#: what remains (half of a gain change), so stopping at one SD left a factor 1.5 SD short
COMPLETED = 0.1


@dataclass
class Judgement:
    """A fix's refit and its held-out errors, for an effect's keep rule. ``parameters`` is the
    effect's report, which a rule may extend."""

    stage: Stage
    new: Stage
    finding: Finding
    parameters: dict
    before: float
    after: float
    p: float
    delta_bic: float
    alpha: float


def try_fix(stage: Stage, finding: Finding, alpha: float, entry) -> tuple[tuple[Effect, Stage] | None, str]:
    """Refit with the finding's effect (``entry``, its :class:`~.effects.EffectKind`);
    ``((Effect, Stage), "")`` if its keep rule says keep it, else ``(None, reason)``."""
    s = stage.model.raw
    refused = entry.refuse(stage, finding) if entry.refuse else ""
    if refused:
        return None, refused
    new = entry.refit(stage, finding, entry)
    if entry.criterion == "simulation" and not (stage.held.simulates and new.held.simulates):
        return None, (
            f"judged on the held-out simulation, which diverges: a half-record model has a mode that grows "
            f"{max(stage.held.growth, new.held.growth):.3g} times over the half it simulates, so its simulation "
            "errors cannot judge the fix"
        )
    affected = entry.judged_on(finding) if entry.judged_on else _affected(finding, s)
    idx = [s.sensors.index(c) for c in affected]
    idx_new = [new.model.signals.sensors.index(c) for c in affected]  # a second input leaves the outputs
    common = stage.held.mask & new.held.mask  # both errors on the same samples (a fix may drop some)
    before, after = _pooled_rms(stage.held, idx, mask=common), _pooled_rms(new.held, idx_new, mask=common)
    kind = entry.criterion
    p = _held_out_p(stage.held, new.held, idx, kind, idx_new)
    shared = new.model.signals.sensors
    dbic = new.bic(kind, shared) - stage.bic(kind, shared)
    params = entry.parameters(finding, new.model)
    params["criterion"] = f"held-out {kind.replace('_', '-')} error"
    if kind == "simulation":
        params["sim_error_before"] = _pooled_rms(stage.held, idx, kind, common)
        params["sim_error_after"] = _pooled_rms(new.held, idx_new, kind, common)
    judgement = Judgement(stage, new, finding, params, before, after, p, dbic, alpha)
    kept, text = entry.keep(judgement)
    if not kept:
        return None, text
    return (Effect(finding, judgement.parameters, before, after, p, dbic, text), new), ""


def _affected(finding: Finding, s: Signals) -> list[str]:
    """The outputs whose error judges a fix: every output for an input's effect, else the
    finding's channels."""
    if finding.channels == (s.input_name,):
        return list(s.sensors)
    return list(finding.channels)


# -- how a fix is refitted ---------------------------------------------------------------------


def refit_spec(stage: Stage, finding: Finding, entry) -> Stage:
    """The model with the effect added to its spec (``entry.add``), refitted from the stage's."""
    s = stage.model.raw
    spec = entry.add(stage.model.spec, finding, stage.model)
    model = fit_model(spec, s, start=widened_start(stage.model, spec))
    return Stage(model, held_out(model.spec, s, model))


def _refit_completed(stage: Stage, finding: Finding, entry, remaining, key: str, as_value) -> Stage:
    """A channel's change taken out of it (``entry.add``), refitted, and completed from the
    refitted model's residual at most ``STEP_PASSES`` times while what remains exceeds its SD: the
    model fitted with the change in the data carried part of it, so the first reading falls short.
    ``remaining(model, finding)`` gives ``(left, sd)``; ``entry.add`` combines the rest, its
    parameter ``key`` set to ``as_value(left)``, with what is taken out there already."""
    s = stage.model.raw
    spec = entry.add(stage.model.spec, finding, stage.model)
    model = fit_model(spec, s, start=widened_start(stage.model, spec))
    for _ in range(STEP_PASSES):
        left, sd = remaining(model, finding)
        if abs(left) < COMPLETED * sd:
            break
        spec = entry.add(spec, replace(finding, parameters={**finding.parameters, key: as_value(left)}), model)
        model = fit_model(spec, s, start=model)
    return Stage(model, held_out(model.spec, s, model))


def _at_sample(remaining):
    """``remaining(model, name, sample)`` read at the finding's channel and sample."""
    return lambda model, f: remaining(model, f.channels[0], int(f.parameters["sample"]))


def refit_level_shift(stage: Stage, finding: Finding, entry) -> Stage:
    """A level shift taken out and its size completed (:func:`_refit_completed`)."""
    return _refit_completed(stage, finding, entry, _at_sample(remaining_step), "size", float)


def refit_gain_change(stage: Stage, finding: Finding, entry) -> Stage:
    """A gain change taken out and its factor completed (:func:`_refit_completed`)."""
    return _refit_completed(stage, finding, entry, _at_sample(remaining_gain), "factor", lambda left: 1 + left)


def refit_clock_drift(stage: Stage, finding: Finding, entry) -> Stage:
    """A clock's drift taken out and its rate completed (:func:`_refit_completed`)."""
    remaining = lambda model, f: remaining_drift(model, f.channels[0])  # noqa: E731
    return _refit_completed(stage, finding, entry, remaining, "rate_ppm", lambda left: 1e6 * left)


def refit_moved(stage: Stage, finding: Finding, entry) -> Stage:
    """A delay: the channel moved, refitted with ``nk`` and ``nb`` chosen again
    (:func:`_moved_and_reordered`)."""
    s = stage.model.raw
    model = _moved_and_reordered(stage.model, entry.add(stage.model.spec, finding, stage.model), finding)
    return Stage(model, held_out(model.spec, s, model))


def refit_piecewise(stage: Stage, finding: Finding, entry) -> Stage:
    """A time change: one model before the change and one after (the finding's payload)."""
    s, change = stage.model.raw, finding.payload
    model = fit_piecewise(stage.model.spec, s, change, start=stage.model)
    return Stage(model, held_out_piecewise(model.spec, s, change, stage.model))


# -- keep rules: (kept, note) or (False, reason) ------------------------------------------------


def significant_drop(j: Judgement) -> tuple[bool, str]:
    """The general rule: the held-out error falls significantly and BIC falls."""
    kind, before, after = _judged_errors(j)
    if j.p >= j.alpha:
        return False, (
            f"named by its test, but the fix did not lower the held-out {kind} error significantly "
            f"({before:.4g} -> {after:.4g}, p = {j.p:.2g}, change in BIC {j.delta_bic:+.1f})"
        )
    if j.delta_bic >= 0:
        return False, (
            f"named by its test; the held-out {kind} error fell ({before:.4g} -> {after:.4g}, p = {j.p:.2g}) but "
            f"BIC rose by {j.delta_bic:.1f}: the fix's parameters cost more than it explains"
        )
    return True, ""


def _judged_errors(j: Judgement) -> tuple[str, float, float]:
    """The held-out error the p and BIC read (one-step or simulation), before and after: a refusal
    quotes the numbers its test judged (it quoted the one-step error beside a simulation p)."""
    if "sim_error_before" in j.parameters:
        return "simulation", j.parameters["sim_error_before"], j.parameters["sim_error_after"]
    return "one-step", j.before, j.after


def delay_kept(j: Judgement) -> tuple[bool, str]:
    """A phase-slope delay need only be no worse (:func:`_judge_delay`); a lead the
    cross-correlation found is beyond B's reach and must lower the error (the general rule)."""
    j.parameters["nk_before"], j.parameters["nk_after"] = j.stage.model.spec.orders[3], j.new.model.spec.orders[3]
    j.parameters["nb_before"], j.parameters["nb_after"] = j.stage.model.spec.orders[1], j.new.model.spec.orders[1]
    if j.finding.statistic == "residual_input_ccf_z":
        return significant_drop(j)
    note, reason = _judge_delay(j.parameters, j.before, j.after, j.p, j.alpha)
    return (True, note) if note else (False, reason)


def fault_kept(j: Judgement) -> tuple[bool, str]:
    """A glitch is a hypothesis (a heavy-tailed disturbance looks alike): the error must drop.
    A stuck run is a fact of the record (:func:`fact_kept`)."""
    if j.finding.statistic != "additive_outlier_z":
        return fact_kept(j)
    if j.p >= j.alpha:
        return False, (
            f"named by its test, but filling the samples did not lower the held-out error significantly "
            f"({j.before:.4g} -> {j.after:.4g}, p = {j.p:.2g})"
        )
    return True, "the spoiled samples are filled from the model and left out of every error"


def fact_kept(j: Judgement) -> tuple[bool, str]:
    """A pile-up at the rail or a stuck run is a fact of the record, not a hypothesis; a few
    clipped samples barely move the error on the others, so the fix only must not hurt."""
    if j.after > j.before * (1 + NO_WORSE):
        return False, f"filling the samples raised the held-out error from {j.before:.4g} to {j.after:.4g}"
    kind = "clipped" if j.finding.effect == "clipping" else "stuck"
    return True, f"the {kind} samples are filled from the model and left out of every error"


def _judge_delay(params: dict, before: float, after: float, p: float, alpha: float) -> tuple[str, str]:
    """``(note, "")`` keeping a phase-slope delay, or ``("", reason)``.

    B's taps absorb a delay within their reach (the baseline's nk was chosen on the delayed
    data), so the moved model, its nk chosen again, need only be no worse -- not significantly
    worse (one-sided Diebold-Mariano) beyond the refit's scatter: two PEM fits of one real
    record from different starts differ by 5 % held out (stiff 1-storey El Centro). The phase
    slope names the delay. (A lead found by the cross-correlation is beyond B's reach: it must
    lower the error, by the general rule.)"""
    moved = f"moved and refitted with nk {params['nk_before']} -> {params['nk_after']} chosen again by BIC"
    if after > before * (1 + NO_WORSE) and 1 - p < alpha:
        return "", f"{moved}, the held-out error rose from {before:.4g} to {after:.4g} (p = {1 - p:.2g})"
    no_worse = after <= before * (1 + NO_WORSE)
    how = "fell" if p < alpha else "is no worse" if no_worse else "is not significantly worse"
    alike = ""
    if "outputs_lag_ms" in params:
        alike = (
            f"every output lags the input by {params['outputs_lag_ms']:.3g} ms alike (spread p = "
            f"{params['spread_p']:.2g}): one delay; "
        )
    why = (
        "the phase slope names and times the delay"
        if p < alpha
        else "the baseline's B taps had absorbed the delay, which the phase slope names and times"
    )
    return f"{alike}{moved}, the held-out error {how} ({before:.4g} -> {after:.4g}); {why}", ""


def _moved_and_reordered(model, spec: ModelSpec, finding: Finding):
    """``spec`` (a channel moved) fitted with ``nk`` and ``nb`` chosen again by BIC, as the
    baseline's were: moving an output ``d`` samples earlier needs ``d`` more non-causal taps
    (a band-limited response leads its input by a few samples), which the baseline's ``nk``,
    chosen on the delayed data, does not allow. Candidates: the baseline's ``nk`` and
    ``NK_REACH`` either side of where the move puts it; ``nb`` keeps the causal taps' count
    (:func:`armaxmodal.estimate.orders.default_nb`). All are scored on the samples every one of them
    can use."""
    s = model.raw
    na, nb0, nc, nk0 = spec.orders
    d = finding.parameters["delay_samples"]
    earlier = -d if finding.channels == (s.input_name,) else d  # the outputs' move against the input
    centre = nk0 - int(round(earlier))
    fits = []
    for nk in sorted({nk0, *range(centre - NK_REACH, centre + NK_REACH + 1)}):
        nb = nb0 - (min(nk, 0) - min(nk0, 0))
        if nb >= 1:
            trial = replace(spec, orders=(na, nb, nc, nk))
            fits.append(fit_model(trial, s, start=model if trial.orders == model.spec.orders else None))
    mask = np.logical_and.reduce([usable(s.n, m.spec) for m in fits])
    return min(fits, key=lambda m: model_bic(m, mask=mask))


def _held_out_p(before: HeldOut, after: HeldOut, idx: list[int], kind: str = "one_step", idx_after=None) -> float:
    """Diebold-Mariano test that the fix lowers the held-out squared one-step (or simulation)
    error of the channels ``idx`` (``idx_after`` in ``after`` when a fix took an output out;
    one-sided; Newey-West variance of the loss difference)."""
    mask = before.mask & after.mask
    idx_after = idx if idx_after is None else idx_after
    e0, e1 = (getattr(before, kind)[mask][:, idx], getattr(after, kind)[mask][:, idx_after])
    scale = np.mean(e0**2, axis=0)
    d = np.sum((e0**2 - e1**2) / scale, axis=1)
    n = d.size
    lag = int(4 * (n / 100) ** (2 / 9))
    dc = d - d.mean()
    var = dc @ dc / n
    for j in range(1, lag + 1):
        var += 2 * (1 - j / (lag + 1)) * (dc[j:] @ dc[:-j]) / n
    z = d.mean() / np.sqrt(max(var, 1e-300) / n)
    return float(stats.norm.sf(z))


def _pooled_rms(held: HeldOut, idx: list[int], kind: str = "one_step", mask: np.ndarray | None = None) -> float:
    """RMS held-out error of the channels ``idx`` over ``mask`` (default: the held-out mask)."""
    mask = held.mask if mask is None else mask
    return float(np.sqrt(np.mean(getattr(held, kind)[mask][:, idx] ** 2)))
