"""The registry of diagnosis effects: one entry per effect, holding all the loop knows of it.

An entry (``EffectKind``) gives the effect's test (a finder that reads the fitted model's
residual and returns ``Finding`` objects), its place in a round (``tier``: a wrong
linear part fires every later test, so linear and structural effects come first), the error that
judges its fix (``criterion``), the fix (``add``: the model spec with the effect added; ``refit``:
how that is fitted), what the refit says of it (``parameters``) and the rule that keeps it
(``keep``). Adding an effect means adding an entry here, its finder and its fix, and their tests.

``run_tests`` runs every entry's test once per round, in the registry's order. A test may
name more than one effect (the joint-force test names a stiffness or a damping nonlinearity):
it runs once and counts once in the Bonferroni correction (sensors x tests).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from armaxmodal.diagnosis import acceptance, evidence, fixes
from armaxmodal.diagnosis.clock_drift import drift_findings
from armaxmodal.diagnosis.delays import delay_findings, late_start, lead_findings
from armaxmodal.diagnosis.finding import Finding
from armaxmodal.diagnosis.gain_change import gain_change_findings
from armaxmodal.diagnosis.joint_forces import joint_force_findings
from armaxmodal.diagnosis.level_shift import level_shift_findings
from armaxmodal.diagnosis.missing_mode import mode_findings
from armaxmodal.diagnosis.model import FittedModel, counted

__all__ = ["EFFECTS", "REGISTRY", "EffectKind", "Evidence", "entry_of", "run_tests", "tier_of"]


@dataclass
class Evidence:
    """What a round's tests read: the fitted model, its one-step errors, the samples counted,
    the family size for the Bonferroni correction, the per-sensor statistics the report shows
    (``table``, filled by the tests), and the findings so far in the round (``found``)."""

    fitted: FittedModel
    eps: np.ndarray
    mask: np.ndarray
    n_tests: int
    table: dict = field(default_factory=lambda: {"whiteness_p": [], "trend_p": [], "line_p": []})
    found: list = field(default_factory=list)

    @cached_property
    def delays(self) -> list[Finding]:
        """The phase-slope delays: the fault test reads them too (a late channel's fill is no
        stuck run)."""
        return delay_findings(self.fitted, self.n_tests)


@dataclass(frozen=True)
class EffectKind:
    """One diagnosis effect (see the module notes). ``refuse(stage, finding)`` returns why no fix
    can be tried ("" to try one); ``judged_on(finding)`` the outputs whose error judges the fix
    (default: every output for an effect on the input, else the finding's channels)."""

    name: str
    test: Callable[[Evidence], list[Finding]]
    tier: int
    add: Callable | None
    parameters: Callable = fixes.finding_parameters
    criterion: str = "one_step"
    refit: Callable = acceptance.refit_spec
    keep: Callable = acceptance.significant_drop
    refuse: Callable | None = None
    judged_on: Callable | None = None


# -- the tests, each with one signature ---------------------------------------------------------


def _clipping(ev: Evidence) -> list[Finding]:
    return evidence.clipping_findings(ev.fitted, ev.n_tests)


def _faults(ev: Evidence) -> list[Finding]:
    return evidence.fault_findings(ev.fitted, ev.eps, ev.mask, ev.n_tests, late_start(ev.fitted, ev.delays))


def _delays(ev: Evidence) -> list[Finding]:
    """The phase slope's delays, then a lead beyond B's reach on the channels not yet timed."""
    timed = {c for f in ev.found + ev.delays for c in f.channels}
    return ev.delays + lead_findings(ev.fitted, ev.n_tests, timed)


def _modes(ev: Evidence) -> list[Finding]:
    return mode_findings(ev.fitted, ev.n_tests, ev.table)


def _level_shifts(ev: Evidence) -> list[Finding]:
    return level_shift_findings(ev.fitted, ev.eps, ev.mask, ev.n_tests, ev.table)


def _gain_changes(ev: Evidence) -> list[Finding]:
    return gain_change_findings(ev.fitted, ev.eps, ev.mask, ev.n_tests, ev.table)


def _clock_drifts(ev: Evidence) -> list[Finding]:
    return drift_findings(ev.fitted, ev.mask, ev.n_tests, ev.table)


def _trends(ev: Evidence) -> list[Finding]:
    return evidence.trend_findings(ev.fitted, ev.eps, ev.mask, ev.n_tests, ev.table)


def _lines(ev: Evidence) -> list[Finding]:
    return evidence.line_findings(ev.fitted, ev.mask, ev.n_tests, ev.table)


def _whiteness(ev: Evidence) -> list[Finding]:
    return evidence.whiteness_findings(ev.fitted, ev.eps, ev.mask, ev.n_tests, ev.table)


def _time_change(ev: Evidence) -> list[Finding]:
    return evidence.time_findings(ev.fitted, ev.mask, ev.n_tests, ev.table)


def _joint_forces(ev: Evidence) -> list[Finding]:
    return joint_force_findings(ev.fitted, ev.eps, ev.mask, ev.n_tests, ev.table)


def _second_input(ev: Evidence) -> list[Finding]:
    return evidence.second_input_findings(ev.fitted, ev.eps, ev.mask, ev.n_tests, ev.table)


def _input_clipped(stage, finding: Finding) -> str:
    if finding.channels != (stage.model.raw.input_name,):
        return ""
    return (
        "the input clipped: the structure felt base motion the record does not hold, so no fix can restore "
        "it; record with a wider range, or analyse a stretch without clipping"
    )


def _explained(finding: Finding) -> list[str]:
    return list(finding.parameters["explains"])


# A disturbance on the output is judged on the simulation error: a one-step predictor can carry a
# line or an offset in its noise model (an undamped pole, A(1)) while the deterministic part -- the
# modes -- is wrong.
REGISTRY: tuple[EffectKind, ...] = (
    EffectKind("clipping", _clipping, 0, fixes.add_clipped, keep=acceptance.fact_kept, refuse=_input_clipped),
    EffectKind("sensor_fault", _faults, 0, fixes.add_fault, keep=acceptance.fault_kept),
    EffectKind("input_delay", _delays, 0, fixes.add_delay, refit=acceptance.refit_moved, keep=acceptance.delay_kept),
    EffectKind("unmodelled_mode", _modes, 1, fixes.add_mode, fixes.mode_parameters, "simulation"),
    EffectKind(
        "level_shift",
        _level_shifts,
        1,
        fixes.add_level_shift,
        fixes.level_shift_parameters,
        "simulation",
        refit=acceptance.refit_level_shift,
    ),
    EffectKind(
        "gain_change",
        _gain_changes,
        1,
        fixes.add_gain_change,
        fixes.gain_change_parameters,
        "simulation",
        refit=acceptance.refit_gain_change,
    ),
    EffectKind(
        "clock_drift",
        _clock_drifts,
        0,
        fixes.add_clock_drift,
        fixes.clock_drift_parameters,
        "simulation",
        refit=acceptance.refit_clock_drift,
    ),
    EffectKind("offset_drift", _trends, 1, fixes.add_trend, fixes.trend_parameters, "simulation"),
    EffectKind("periodic_disturbance", _lines, 1, fixes.add_line, fixes.line_parameters, "simulation"),
    EffectKind("coloured_noise", _whiteness, 2, fixes.add_noise_model, fixes.noise_model_parameters),
    EffectKind(
        "time_varying",
        _time_change,
        3,
        None,
        fixes.time_change_parameters,
        "simulation",
        refit=acceptance.refit_piecewise,
    ),
    EffectKind(
        "stiffness_nonlinearity", _joint_forces, 3, fixes.add_joint_force, fixes.joint_force_parameters, "simulation"
    ),
    EffectKind(
        "damping_nonlinearity", _joint_forces, 3, fixes.add_joint_force, fixes.joint_force_parameters, "simulation"
    ),
    EffectKind(
        "second_input", _second_input, 1, fixes.add_second_input, fixes.second_input_parameters, judged_on=_explained
    ),
)
#: The vocabulary of effects (the JSON's ``effect``), in the order the tests run.
EFFECTS = tuple(entry.name for entry in REGISTRY)
#: Effects whose fix acts on every sensor (a trend, a richer C, a pole pair): one finding each,
#: listing every sensor where the test is significant.
PER_RECORD = ("offset_drift", "coloured_noise", "unmodelled_mode")


def entry_of(effect: str) -> EffectKind:
    """The registry's entry of ``effect``."""
    for entry in REGISTRY:
        if entry.name == effect:
            return entry
    raise KeyError(f"no effect {effect!r} in the registry; known: {', '.join(e.name for e in REGISTRY)}")


def _tests() -> list[Callable[[Evidence], list[Finding]]]:
    """Each entry's test once, in the registry's order."""
    out = []
    for entry in REGISTRY:
        if entry.test not in out:
            out.append(entry.test)
    return out


def run_tests(fitted: FittedModel, alpha: float = 0.01) -> tuple[list[Finding], dict]:
    """Every effect test on ``fitted``; returns the significant findings (corrected p below
    ``alpha``) and the per-sensor statistics for the report."""
    tests = _tests()
    ev = Evidence(fitted, fitted.one_step_errors(), counted(fitted), len(tests) * len(fitted.signals.sensors))
    for test in tests:
        ev.found += test(ev)
    significant = [f for f in ev.found if f.p < alpha]
    return evidence.merge_per_sensor(significant, PER_RECORD), ev.table


def tier_of(finding: Finding) -> int:
    """The finding's place in a round. A lead found by the residual-input cross-correlation
    waits for the disturbances and missing modes (the tier of ``coloured_noise``): their misfit
    also correlates with the input near the model's reach; a phase-slope delay comes first."""
    if finding.statistic == "residual_input_ccf_z":
        return entry_of("coloured_noise").tier
    return entry_of(finding.effect).tier
