"""What the diagnosis found: the stages (a fitted model with its held-out errors), the effects
kept, and the report (:class:`~armaxmodal.diagnosis.Diagnosis`, whose ``to_dict`` is the JSON of
``armaxmodal diagnose``)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from armaxmodal.diagnosis.evidence import whiteness_p
from armaxmodal.diagnosis.finding import Finding
from armaxmodal.diagnosis.model import LINE_MERGE_HZ, UNDAMPED, FittedModel, HeldOut, model_bic
from armaxmodal.recording import Recording

__all__ = ["Diagnosis", "Effect", "Stage", "stage_modes"]


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
        sim_rms = np.sqrt(np.mean(self.held.simulation[self.held.mask] ** 2, axis=0)).tolist()
        diverged = [None] * len(s.sensors)  # a diverging simulation's error is its growth, not a fit
        return {
            "fit_val_pct": self.held.fit_percent(y).tolist() if self.held.simulates else diverged,
            "one_step_fit_pct": (100 * (1 - np.linalg.norm(e1, axis=0) / np.linalg.norm(yy, axis=0))).tolist(),
            "resid_rms": self.held.rms().tolist(),
            "sim_resid_rms": sim_rms if self.held.simulates else diverged,
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

    def judged_by(self) -> dict:
        """The held-out error that judged the fix (``"one-step"`` or ``"simulation"``), before and
        after: the one the keep rule read, which falls for every effect kept."""
        if "simulation" in self.parameters.get("criterion", ""):
            return {
                "error": "simulation",
                "before": self.parameters["sim_error_before"],
                "after": self.parameters["sim_error_after"],
            }
        return {"error": "one-step", "before": self.error_before, "after": self.error_after}

    def to_dict(self) -> dict:
        out = {
            "effect": self.finding.effect,
            "channels": list(self.finding.channels),
            "evidence": self.finding.evidence(),
            "parameters": self.parameters,
            "error_before": self.error_before,
            "error_after": self.error_after,
            "judged_by": self.judged_by(),
            "held_out_p": self.dm_p,
            "delta_bic": self.delta_bic,
        }
        if self.note:
            out["note"] = self.note
        return out


@dataclass(frozen=True)
class Diagnosis:
    """What :func:`~armaxmodal.diagnosis.diagnose` found. ``to_dict`` is the JSON contract of
    ``armaxmodal diagnose``.

    See Also
    --------
    armaxmodal.diagnosis.diagnose : What makes one.

    Examples
    --------
    >>> import armaxmodal as am
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)
    >>> from armaxmodal.diagnosis.inject import inject
    >>> hum = inject(ride, "periodic_disturbance", ["head"], freq_hz=11.7, amp=0.1)
    >>> (effect,) = am.diagnose(hum, max_rounds=1).effects
    >>> effect.finding.effect, effect.finding.channels, round(effect.parameters["freq_hz"], 1)
    ('periodic_disturbance', ('head',), 11.7)
    """

    baseline: Stage
    final: Stage
    effects: tuple[Effect, ...]
    unconfirmed: tuple[dict, ...]
    #: ``{output: RMS}``, ``None`` where the record cannot resolve it (``noise_floor.noise_floor``).
    noise_floor: dict
    recording: Recording
    original_fs: float
    warnings: tuple = ()
    tests: dict = field(default_factory=dict)

    @property
    def sensors(self) -> tuple[str, ...]:
        return self.baseline.model.signals.sensors

    def modes(self, stage: Stage) -> pd.DataFrame:
        """The physical modes of a stage's model (identify's rejection rules).

        Parameters
        ----------
        stage : Stage
            One of the diagnosis's stages (``baseline`` or ``final``).

        Returns
        -------
        pandas.DataFrame
            One row per physical mode: ``freq_hz``, ``damping`` and the 95 % interval of the
            frequency.
        """
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
        from armaxmodal._version import __version__

        return {
            "armaxmodal_version": __version__,
            "verdict": _verdict(self, final["whiteness_p"]),
            "fs": self.original_fs,
            "analysis_fs": self.recording.fs,
            "input": self.recording.input_name,
            "outputs": list(self.sensors),
            "orders": {"na": na, "nb": nb, "nc": nc, "nk": nk, "shared_poles": True},
            "validation": "two blocked folds: each half predicted by the model fitted on the other half",
            # how much a fold model's fastest mode grows over the half it simulates; beyond 100 the
            # simulation diverges and its fits are null
            "simulation_growth": {"baseline": self.baseline.held.growth, "final": self.final.held.growth},
            "baseline": self.baseline.summary(self.noise_floor),
            "effects": [e.to_dict() for e in self.effects],
            "unconfirmed": list(self.unconfirmed),
            "final": final,
            "tests": self.tests,
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


def _verdict(diagnosis: Diagnosis, whiteness: list[float], alpha: float = 0.01) -> str:
    """One sentence a person can act on: what was found and confirmed first (each effect, where,
    and its held-out error before and after), then what is left; "unsure" only where nothing was
    confirmed and a test fired (a dry friction confirmed as a damping nonlinearity read "unsure",
    for two side tests whose fixes did not help)."""
    held = diagnosis.baseline.held
    diverges = (
        (
            f" The baseline's held-out simulation diverges (a half-record model has a mode that grows "
            f"{held.growth:.3g} times over the half it simulates: the record is too short or too nonstationary "
            "for the model's order), so no fix judged on simulation can be confirmed."
        )
        if not held.simulates
        else ""
    )
    return _findings_verdict(diagnosis, whiteness, alpha) + diverges


def _found(effect: Effect) -> str:
    """An effect kept, as the verdict names it: where, and the held-out error that judged it."""
    judged = effect.judged_by()
    return (
        f"{effect.finding.effect}{_place(effect)} on {', '.join(effect.finding.channels)} (held-out "
        f"{judged['error']} error {judged['before']:.3g} -> {judged['after']:.3g})"
    )


def _place(effect: Effect) -> str:
    """A joint force's term and joint, as the verdict names it ("" for other effects)."""
    from armaxmodal.diagnosis.joint_forces import TERM_WORDS

    p = effect.parameters
    return f" ({TERM_WORDS[p['term']]} between {' and '.join(p['between'])})" if "between" in p else ""


def _findings_verdict(diagnosis: Diagnosis, whiteness: list[float], alpha: float) -> str:
    """What was found and confirmed, then what is left (:func:`_verdict`)."""
    coloured = [s for s, p in zip(diagnosis.sensors, whiteness, strict=True) if p is not None and p < alpha]
    left = (
        (
            f"the residual of {', '.join(coloured)} is still not white after the fixes; an effect the fixes do not "
            "capture (a non-smooth nonlinearity such as friction or a clearance, a time change, a missing mode) may "
            "remain. Look at the figure."
        )
        if coloured
        else ""
    )
    if diagnosis.effects:
        found = "; ".join(_found(e) for e in diagnosis.effects)
        if left:
            return f"found and confirmed: {found}. But {left}"
        if diagnosis.unconfirmed:
            return (
                f"found and confirmed: {found}; the effects listed explain the residual (white after the fixes). "
                "Other tests fired whose fixes did not lower the held-out error (see 'unconfirmed')."
            )
        return f"found and confirmed: {found}; the effects listed explain the residual (white after the fixes)."
    if left:
        return f"unsure: {left}"
    if diagnosis.unconfirmed:
        return "unsure: some tests fired but their fixes did not lower the held-out error (see 'unconfirmed')."
    return "no effect: the residual is consistent with the model."
