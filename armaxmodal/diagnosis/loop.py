"""The loop: fit the baseline, test its residual, add the strongest effect, keep it only if the
held-out error says so, repeat (at most a few rounds)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd
from scipy import stats

from armaxmodal._threads import single_blas_thread
from armaxmodal.diagnosis.delays import cross_correlation
from armaxmodal.diagnosis.evidence import EFFECT_TESTS, run_tests, whiteness_p
from armaxmodal.diagnosis.finding import Finding
from armaxmodal.diagnosis.fixes import add_effect, effect_parameters
from armaxmodal.diagnosis.model import (
    LINE_MERGE_HZ,
    UNDAMPED,
    FittedModel,
    HeldOut,
    ModelSpec,
    PiecewiseModel,
    Signals,
    fit_model,
    fit_piecewise,
    held_out,
    held_out_piecewise,
    model_bic,
    usable,
    widened_start,
)
from armaxmodal.exceptions import DataError
from armaxmodal.prepare.frf import coherence, welch_spectra
from armaxmodal.prepare.preparation import prepare
from armaxmodal.recording import Recording
from armaxmodal.stats import welch_nperseg

__all__ = ["diagnose", "Diagnosis", "EFFECTS", "TESTED_EFFECTS"]

#: The fixed vocabulary of effects (the JSON's ``effect``).
EFFECTS = (
    "input_delay",
    "offset_drift",
    "periodic_disturbance",
    "stiffness_nonlinearity",
    "unmodelled_mode",
    "coloured_noise",
    "clipping",
    "time_varying",
    "second_input",
    "sensor_fault",
)
#: The effects this version tests and fixes; the others are listed as not tested.
TESTED_EFFECTS = EFFECT_TESTS
#: Linear/structural effects first: a wrong linear part fires every later test.
_TIER = {
    "clipping": 0,
    "sensor_fault": 0,
    "input_delay": 0,
    "unmodelled_mode": 1,
    "offset_drift": 1,
    "periodic_disturbance": 1,
    "coloured_noise": 2,
    "time_varying": 3,
    "stiffness_nonlinearity": 3,
    "second_input": 1,
}
#: A disturbance on the output is judged on the simulation error: a one-step predictor can
#: carry a line or an offset in its noise model (an undamped pole, A(1)) while the
#: deterministic part -- the modes -- is wrong.
_CRITERION = {
    "unmodelled_mode": "simulation",
    "periodic_disturbance": "simulation",
    "offset_drift": "simulation",
    "stiffness_nonlinearity": "simulation",
    "time_varying": "simulation",
}
#: A fix that must only not hurt (a delay the B taps absorbed, a clipped or stuck run filled)
#: may raise the held-out error by this fraction: the refit's own scatter.
NO_WORSE = 0.01
#: nk candidates either side of where a delay's move puts the baseline's (and the baseline's).
NK_REACH = 1
#: Fewer samples than this per half cannot hold out a validation part.
MIN_SAMPLES = 400


@dataclass(frozen=True)
class Stage:
    """A fitted model with its held-out errors."""

    model: FittedModel
    held: HeldOut

    def bic(self, kind: str = "one_step", channels=None) -> float:
        """:func:`~.model.model_bic` of the stage's model."""
        return model_bic(self.model, kind, channels)

    def summary(self, noise_floor: dict) -> dict:
        s = self.model.signals
        y = s.y
        e1 = self.held.one_step[self.held.mask]
        yy = y[self.held.mask] - y[self.held.mask].mean(axis=0)
        return {
            "fit_val_pct": self.held.fit_percent(y).tolist(),
            "one_step_fit_pct": (100 * (1 - np.linalg.norm(e1, axis=0) / np.linalg.norm(yy, axis=0))).tolist(),
            "resid_rms": self.held.rms().tolist(),
            "sim_resid_rms": np.sqrt(np.mean(self.held.simulation[self.held.mask] ** 2, axis=0)).tolist(),
            "noise_floor_rms": [noise_floor.get(name) for name in s.sensors],
            "whiteness_p": whiteness_p(self.model),
        }


@dataclass(frozen=True)
class Effect:
    """An accepted effect: the finding, its fitted parameters and the errors around the fix."""

    finding: Finding
    parameters: dict
    error_before: float
    error_after: float
    dm_p: float
    delta_bic: float
    note: str = ""

    def to_dict(self) -> dict:
        out = {
            "effect": self.finding.effect,
            "channels": list(self.finding.channels),
            "evidence": self.finding.evidence(),
            "parameters": self.parameters,
            "error_before": self.error_before,
            "error_after": self.error_after,
            "held_out_p": self.dm_p,
            "delta_bic": self.delta_bic,
        }
        if self.note:
            out["note"] = self.note
        return out


@dataclass(frozen=True)
class Diagnosis:
    """What :func:`diagnose` found. ``to_dict`` is the JSON contract of ``armaxmodal diagnose``."""

    baseline: Stage
    final: Stage
    effects: tuple[Effect, ...]
    unconfirmed: tuple[dict, ...]
    #: ``{output: RMS}``, ``None`` where the record cannot resolve it (:func:`_noise_floor`).
    noise_floor: dict
    recording: Recording
    original_fs: float
    warnings: tuple = ()
    tests: dict = field(default_factory=dict)

    @property
    def sensors(self) -> tuple[str, ...]:
        return self.baseline.model.signals.sensors

    def modes(self, stage: Stage) -> pd.DataFrame:
        """The physical modes of a stage's model (identify's rejection rules)."""
        return stage_modes(stage, self.recording)

    def _repr_html_(self) -> str:
        """A notebook's view: the verdict and each effect with its evidence and error before and after."""
        import html

        from armaxmodal.diagnosis.report import effects_table

        report = self.to_dict()
        table = effects_table(report).to_html(index=False, float_format=lambda v: f"{v:.4g}", border=0)
        return f"<p><b>verdict: {html.escape(report['verdict'])}</b></p>{table}"

    def to_dict(self) -> dict:
        na, nb, nc, nk = self.baseline.model.spec.orders

        def modes(stage):
            return [{k: float(v) for k, v in row.items()} for row in self.modes(stage).to_dict("records")]

        final = _per_output(self.final.summary(self.noise_floor), self.final.model.signals.sensors, self.sensors)
        final.update(modes_before=modes(self.baseline), modes_after=modes(self.final))
        return {
            "verdict": _verdict(self, final["whiteness_p"]),
            "fs": self.original_fs,
            "analysis_fs": self.recording.fs,
            "input": self.recording.input_name,
            "outputs": list(self.sensors),
            "orders": {"na": na, "nb": nb, "nc": nc, "nk": nk, "shared_poles": True},
            "validation": "two blocked folds: each half predicted by the model fitted on the other half",
            "baseline": self.baseline.summary(self.noise_floor),
            "effects": [e.to_dict() for e in self.effects],
            "unconfirmed": list(self.unconfirmed),
            "final": final,
            "tests": self.tests,
            "not_tested": [e for e in EFFECTS if e not in TESTED_EFFECTS],
            "warnings": [w.to_dict() for w in self.warnings],
        }


def stage_modes(stage: Stage, recording: Recording) -> pd.DataFrame:
    """The physical modes of a stage's model (identify's rejection rules), without a pole
    pair that duplicates a modelled line."""
    from armaxmodal.modes.poles import POLE_COLUMNS, SHARED, Tolerances, pole_rows, rejection_reasons

    poles = pd.DataFrame(pole_rows(stage.model.fit, SHARED), columns=POLE_COLUMNS)
    poles = poles[np.array(rejection_reasons(poles, Tolerances(), recording)) == ""]
    for f in stage.model.spec.lines_hz:
        poles = poles[~((abs(poles.freq_hz - f) < LINE_MERGE_HZ) & (poles.damping < UNDAMPED))]
    return poles.sort_values("freq_hz")[["freq_hz", "damping", "freq_ci95_lo", "freq_ci95_hi"]]


def _per_output(summary: dict, sensors, outputs) -> dict:
    """``summary``'s per-sensor lists over ``outputs`` (the recording's), ``None`` where an
    output became an input (a second input); ``inputs_added`` names those."""
    out = {}
    for key, values in summary.items():
        by_name = dict(zip(sensors, values, strict=True))
        out[key] = [by_name.get(name) for name in outputs]
    out["inputs_added"] = [name for name in outputs if name not in sensors]
    return out


def _tier(finding: Finding) -> int:
    """The finding's place in a round. A lead found by the residual-input cross-correlation
    waits for the disturbances and missing modes (tier 1): their misfit also correlates with
    the input near the model's reach; a phase-slope delay comes first."""
    if finding.statistic == "residual_input_ccf_z":
        return _TIER["coloured_noise"]
    return _TIER[finding.effect]


def _verdict(diagnosis: Diagnosis, whiteness: list[float], alpha: float = 0.01) -> str:
    """One sentence a person can act on, unsure where the data leave doubt."""
    coloured = [s for s, p in zip(diagnosis.sensors, whiteness, strict=True) if p is not None and p < alpha]
    if coloured:
        return (
            f"unsure: the residual of {', '.join(coloured)} is still not white after the fixes; an effect the "
            "fixes do not capture (a non-smooth nonlinearity such as friction or a clearance, a time change, a "
            "missing mode) may remain. Look at the figure."
        )
    if diagnosis.unconfirmed:
        return "unsure: some tests fired but their fixes did not lower the held-out error (see 'unconfirmed')."
    if diagnosis.effects:
        return "the effects listed explain the residual: it is white after the fixes."
    return "no effect: the residual is consistent with the model."


def _signals(recording: Recording, band) -> tuple[Signals, Recording, tuple]:
    """The record as recorded (no detrend, no alignment: those are what is tested), resampled
    to the band when it is sampled far above it."""
    prep = prepare(recording, band=band, detrend="none", align=False, drop_incoherent=False)
    rec = prep.recording
    if rec.n_samples < 2 * MIN_SAMPLES:
        raise DataError(
            f"diagnose: the record has {rec.n_samples} samples at {rec.fs:g} Hz; holding out half of it for "
            f"validation needs at least {2 * MIN_SAMPLES}. Use a longer recording."
        )
    kept = ("duplicate_channel", "resampled", "clipping", "narrowband_input", "incoherent_output", "offset_step")
    keep = tuple(w for w in prep.warnings if w.code in kept)
    return Signals(rec.base, rec.response, rec.fs, rec.sensors, rec.input_name), rec, keep


def _baseline_orders(rec: Recording, baseline) -> tuple[int, int, int, int]:
    from armaxmodal.estimate.orders import choose_orders
    from armaxmodal.modes.identification import Identification

    if baseline is None:
        centred = prepare(rec, detrend="mean", align=False, resample=False, drop_incoherent=False).recording
        return choose_orders(centred).orders
    fit = baseline.fit if isinstance(baseline, Identification) else baseline
    if tuple(fit.sensors) != tuple(rec.sensors) or not np.isclose(fit.fs, rec.fs):
        raise DataError(
            f"baseline: the model was fitted to sensors {list(fit.sensors)} at {fit.fs:g} Hz, this record has "
            f"{list(rec.sensors)} at {rec.fs:g} Hz; give a model of this recording or none (it is then chosen by BIC)."
        )
    return fit.orders


def _extra_input_response(model) -> np.ndarray:
    """The response to the model's second inputs, (n, K): what the noise floor, a coherence
    with the base alone, must not count as noise. Not a nonlinear term's: built from the
    response to the base, it is collinear with it, and its B alone may be large where the
    base's B cancels it (on the F-16 the floor rose above the residual tenfold)."""
    if isinstance(model, PiecewiseModel):
        return model._join(*(_extra_input_response(m) for m in (model.before, model.after)))
    u = model.signals.inputs(model.spec).copy()
    second = [1 + i for i, name in enumerate(model.spec.terms) if name in model.spec.inputs_from]
    u[:, [m for m in range(u.shape[1]) if m not in second]] = 0.0
    if not second:
        return np.zeros_like(model.signals.y)
    return np.column_stack([m.simulate(u) for m in model.fit.models])


def _noise_floor(s: Signals, mask: np.ndarray, linear_error: dict | None = None) -> dict:
    """``{output: RMS}`` of the output part not coherent with the input (Welch H1): what a
    perfect linear model of this input would still leave in its simulation error; ``None``
    where the record cannot resolve it.

    Short segments smear a lightly damped peak, and the coherence there drops for want of
    resolution, not for noise: on the F-16 (0.5 % damping, 10 s segments) the floor came out
    three times the linear model's own held-out error. So the segment doubles from 10 s (at
    most an eighth of the record) while that lowers the floor by more than ``FLOOR_SETTLED``,
    the longer one up to a quarter of the record; a floor still falling there is not resolved.
    Nor is one above ``linear_error`` (``{output: RMS}``, a linear model's held-out simulation
    error, which the floor bounds from below): both segments may be far too short."""
    u, y = s.u[mask], s.y[mask]
    nperseg = welch_nperseg(u.size, s.fs)
    floor = _welch_floor(u, y, s.fs, nperseg)
    settled = np.zeros(floor.size, bool)
    while not settled.all() and 2 * nperseg <= u.size // 4:
        nperseg *= 2
        finer = _welch_floor(u, y, s.fs, nperseg)
        settled |= finer >= (1 - FLOOR_SETTLED) * floor
        floor = np.where(settled, floor, finer)
    bound = linear_error or {}
    settled &= np.array([floor[k] <= bound.get(name, np.inf) for k, name in enumerate(s.sensors)])
    return {name: float(v) if ok else None for name, v, ok in zip(s.sensors, floor, settled, strict=True)}


#: Relative drop of the noise floor on doubling the segment below which it has settled.
FLOOR_SETTLED = 0.2


def _welch_floor(u: np.ndarray, y: np.ndarray, fs: float, nperseg: int) -> np.ndarray:
    f, puu, puy, pyy = welch_spectra(u, y, fs, nperseg)
    coh = coherence(puu, puy, pyy)
    return np.sqrt(np.sum((1 - coh) * pyy, axis=0) * (f[1] - f[0]))


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


@single_blas_thread
def diagnose(
    recording: Recording,
    baseline=None,
    *,
    band: tuple[float, float] | None = None,
    alpha: float = 0.01,
    max_rounds: int = 3,
    progress: bool = False,
) -> Diagnosis:
    """Find what the model lacks, add it, refit, and report the error before and after.

    Parameters
    ----------
    recording : Recording
        As recorded: the diagnosis removes no mean and aligns nothing, as offsets and delays
        are among what it tests (a record sampled far above its band is resampled).
    baseline : Identification or ArmaxFit, optional
        The model to start from; by default the orders chosen by BIC (as ``identify``).
    band : (lo, hi), optional
        Band of interest, Hz (sets the analysis rate as in ``stabilise``).
    alpha : float
        Family-wise significance of the tests (corrected for sensors x tests) and of the
        held-out error drop a fix must show.
    max_rounds : int
        Effects added at most.
    progress : bool
        Print each stage.

    Returns
    -------
    Diagnosis
    """
    if not isinstance(recording, Recording):
        raise DataError(f"recording: expected a Recording, got {type(recording).__name__}.")
    if not (0 < alpha < 0.5) or int(max_rounds) != max_rounds or max_rounds < 0:
        raise DataError(f"alpha must be in (0, 0.5) and max_rounds a whole number >= 0; got {alpha!r}, {max_rounds!r}.")
    signals, rec, warnings = _signals(recording, band)
    orders = _baseline_orders(rec, baseline)
    say = print if progress else (lambda *a, **k: None)
    say(f"baseline: shared-pole ARMAX {orders} on {signals.n} samples at {signals.fs:g} Hz")
    spec = ModelSpec(tuple(int(v) for v in orders))
    model = fit_model(spec, signals)
    stage = first = Stage(model, held_out(spec, signals, model))
    effects, unconfirmed, tests = [], {}, {}
    for round_no in range(int(max_rounds)):
        findings, tests = run_tests(stage.model, alpha)
        findings.sort(key=lambda f: (_tier(f), f.p, -f.value))
        say(f"round {round_no + 1}: " + (", ".join(f"{f.effect} {list(f.channels)}" for f in findings) or "no effect"))
        step = None
        for finding in findings:
            step, reason = _try_fix(stage, finding, alpha)
            if step is not None:
                break
            # one entry per effect and channels, from the latest round that tried it
            unconfirmed[(finding.effect, frozenset(finding.channels))] = {
                "effect": finding.effect, "channels": list(finding.channels), "reason": reason,
                "evidence": finding.evidence()}  # fmt: skip
        if step is None:
            break
        effect, stage = step
        effects.append(effect)
        unconfirmed.pop((effect.finding.effect, frozenset(effect.finding.channels)), None)
        if isinstance(stage.model, PiecewiseModel):
            break  # the tests assume one model; a record split in two is reported as it is
    if effects:
        tests = run_tests(stage.model, alpha)[1]
    raw = stage.model.raw  # without an output a second input took
    own = raw.y - stage.model.disturbance() - _extra_input_response(stage.model)
    clean = Signals(raw.u, own, raw.fs, raw.sensors, raw.input_name)
    held = first.held  # the baseline is linear in the base: its error bounds the floor
    sim_rms = np.sqrt(np.mean(held.simulation[held.mask] ** 2, axis=0))
    floor = _noise_floor(clean, usable(signals.n, spec), dict(zip(first.model.signals.sensors, sim_rms, strict=True)))
    tests["cross_correlation"] = cross_correlation(stage.model)
    unsure = tuple(unconfirmed.values())
    return Diagnosis(first, stage, tuple(effects), unsure, floor, rec, recording.fs, warnings, tests)


def _affected(finding: Finding, s: Signals) -> list[str]:
    """The outputs whose error judges a fix: every output for an input's effect, the channels
    a second input explains, else the finding's channels."""
    if finding.channels == (s.input_name,):
        return list(s.sensors)
    if finding.effect == "second_input":
        return list(finding.parameters["explains"])
    return list(finding.channels)


def _try_fix(stage: Stage, finding: Finding, alpha: float):
    """Refit with the finding's effect; ``((Effect, Stage), "")`` if the held-out error says
    keep it, else ``(None, reason)``."""
    s = stage.model.raw
    on_input = finding.channels == (s.input_name,)
    if finding.effect == "clipping" and on_input:
        return None, (
            "the input clipped: the structure felt base motion the record does not hold, so no fix can restore "
            "it; record with a wider range, or analyse a stretch without clipping"
        )
    if finding.effect == "time_varying":
        change = finding.payload
        model = fit_piecewise(stage.model.spec, s, change, start=stage.model)
        new = Stage(model, held_out_piecewise(model.spec, s, change, stage.model))
    elif finding.effect == "input_delay":
        model = _moved_and_reordered(stage.model, add_effect(stage.model.spec, finding, stage.model), finding)
        new = Stage(model, held_out(model.spec, s, model))
    else:
        spec = add_effect(stage.model.spec, finding, stage.model)
        model = fit_model(spec, s, start=widened_start(stage.model, spec))
        new = Stage(model, held_out(model.spec, s, model))
    affected = _affected(finding, s)
    idx = [s.sensors.index(c) for c in affected]
    idx_new = [new.model.signals.sensors.index(c) for c in affected]  # a second input leaves the outputs
    common = stage.held.mask & new.held.mask  # both errors on the same samples (a fix may drop some)
    before, after = _pooled_rms(stage.held, idx, mask=common), _pooled_rms(new.held, idx_new, mask=common)
    kind = _CRITERION.get(finding.effect, "one_step")
    p = _held_out_p(stage.held, new.held, idx, kind, idx_new)
    shared = new.model.signals.sensors
    dbic = new.bic(kind, shared) - stage.bic(kind, shared)
    params = effect_parameters(finding, model)
    params["criterion"] = f"held-out {kind.replace('_', '-')} error"
    if kind == "simulation":
        params["sim_error_before"] = _pooled_rms(stage.held, idx, kind, common)
        params["sim_error_after"] = _pooled_rms(new.held, idx_new, kind, common)
    if finding.effect == "input_delay":
        params["nk_before"], params["nk_after"] = stage.model.spec.orders[3], model.spec.orders[3]
        params["nb_before"], params["nb_after"] = stage.model.spec.orders[1], model.spec.orders[1]
    if finding.effect == "input_delay" and finding.statistic != "residual_input_ccf_z":
        note, reason = _judge_delay(params, before, after, p, alpha)
        return ((Effect(finding, params, before, after, p, dbic, note), new), "") if note else (None, reason)
    if finding.effect == "sensor_fault" and finding.statistic == "additive_outlier_z":
        # a glitch is a hypothesis (a heavy-tailed disturbance looks alike): the error must drop
        if p >= alpha:
            return None, (
                f"named by its test, but filling the samples did not lower the held-out error significantly "
                f"({before:.4g} -> {after:.4g}, p = {p:.2g})"
            )
        note = "the spoiled samples are filled from the model and left out of every error"
        return (Effect(finding, params, before, after, p, dbic, note), new), ""
    if finding.effect in ("clipping", "sensor_fault"):
        # a pile-up at the rail or a stuck run is a fact of the record, not a hypothesis;
        # a few clipped samples barely move the error on the others, so the fix only must not hurt
        if after > before * (1 + NO_WORSE):
            return None, f"filling the samples raised the held-out error from {before:.4g} to {after:.4g}"
        kind = "clipped" if finding.effect == "clipping" else "stuck"
        note = f"the {kind} samples are filled from the model and left out of every error"
        return (Effect(finding, params, before, after, p, dbic, note), new), ""
    if p >= alpha or dbic >= 0:
        return None, (
            f"named by its test, but the fix did not lower the held-out error significantly "
            f"({before:.4g} -> {after:.4g}, p = {p:.2g}, change in BIC {dbic:+.1f})"
        )
    return (Effect(finding, params, before, after, p, dbic), new), ""


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
