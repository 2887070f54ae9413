"""The loop: fit the baseline, test its residual, add the strongest effect, keep it only if the
held-out error says so, repeat (at most a few rounds).

What each effect is -- its test, fix, tier, criterion and keep rule -- is the registry's
(:mod:`~armaxmodal.diagnosis.effects`); the rule that keeps a fix is
:mod:`~armaxmodal.diagnosis.acceptance`'s; the report is :mod:`~armaxmodal.diagnosis.result`'s and the
noise floor it is read against :mod:`~armaxmodal.diagnosis.noise_floor`'s.
"""

from __future__ import annotations

import numpy as np

from armaxmodal._threads import single_blas_thread
from armaxmodal.diagnosis.acceptance import try_fix
from armaxmodal.diagnosis.delays import cross_correlation
from armaxmodal.diagnosis.effects import EFFECTS, entry_of, run_tests, tier_of
from armaxmodal.diagnosis.model import ModelSpec, PiecewiseModel, Signals, fit_model, held_out, usable
from armaxmodal.diagnosis.noise_floor import extra_input_response, noise_floor
from armaxmodal.diagnosis.result import Diagnosis, Stage
from armaxmodal.exceptions import DataError
from armaxmodal.prepare.preparation import prepare
from armaxmodal.recording import Recording

__all__ = ["EFFECTS", "Diagnosis", "diagnose"]

#: Fewer samples than this per half cannot hold out a validation part.
MIN_SAMPLES = 400


def _signals(recording: Recording, band) -> tuple[Signals, Recording, tuple]:
    """The record as recorded (no detrend, no alignment: those are what is tested), resampled
    to the band when it is sampled far above it, unless that leaves too few samples to hold half
    out (Meloland's 1979 record: 2,196 samples at 100 Hz, 549 at the band's 25 Hz)."""
    prep = prepare(recording, band=band, detrend="none", align=False, drop_incoherent=False)
    if prep.recording.n_samples < 2 * MIN_SAMPLES <= recording.n_samples:
        prep = prepare(recording, band=band, detrend="none", align=False, drop_incoherent=False, resample=False)
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
    from armaxmodal.identification import Identification

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

    See Also
    --------
    armaxmodal.identify : The model whose residual is diagnosed.
    armaxmodal.fit_armax : The ARMAX fit alone.

    Examples
    --------
    A hum at 11.7 Hz on the head sensor, which the model of the ride lacks:

    >>> import armaxmodal as am
    >>> from armaxmodal.diagnosis.inject import inject
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 120.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)
    >>> hum = inject(ride, "periodic_disturbance", ["head"], freq_hz=11.7, amp=0.1)
    >>> (effect,) = am.diagnose(hum, max_rounds=1).effects
    >>> effect.finding.effect, effect.finding.channels, round(effect.parameters["freq_hz"], 1)
    ('periodic_disturbance', ('head',), 11.7)
    >>> effect.error_after < effect.error_before
    True
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
        findings.sort(key=lambda f: (tier_of(f), f.p, -f.value))
        say(f"round {round_no + 1}: " + (", ".join(f"{f.effect} {list(f.channels)}" for f in findings) or "no effect"))
        step = None
        for finding in findings:
            step, reason = try_fix(stage, finding, alpha, entry_of(finding.effect))
            if step is not None:
                break
            # one entry per effect and channels, from the latest round that tried it
            unconfirmed[(finding.effect, frozenset(finding.channels))] = {
                "effect": finding.effect,
                "channels": list(finding.channels),
                "reason": reason,
                "evidence": finding.evidence(),
            }
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
    own = raw.y - stage.model.disturbance() - extra_input_response(stage.model)
    clean = Signals(raw.u, own, raw.fs, raw.sensors, raw.input_name)
    held = first.held  # the baseline is linear in the base: its error bounds the floor
    sim_rms = np.sqrt(np.mean(held.simulation[held.mask] ** 2, axis=0))
    floor = noise_floor(clean, usable(signals.n, spec), dict(zip(first.model.signals.sensors, sim_rms, strict=True)))
    tests["cross_correlation"] = cross_correlation(stage.model)
    unsure = tuple(unconfirmed.values())
    return Diagnosis(first, stage, tuple(effects), unsure, floor, rec, recording.fs, warnings, tests)
