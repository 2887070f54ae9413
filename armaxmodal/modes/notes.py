"""The notes of the selection written from what the stages found: the FRF check's (a mode it does
not need), the count's (:mod:`armaxmodal.modes.mode_count`: what the search did, where the record does
not decide the number of modes, what the picks are worth, which poles stay in the model unreported)
and the final modes' (two the record does not separate, a damping it does not resolve). No decision
is taken here: each note reads a result and its levels (the oversampled record's: ``prepare.resample``)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from armaxmodal.modes.intervals import not_separated, with_intervals
from armaxmodal.modes.mode_count import ModeCount, reported
from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.stats import MAX_DAMPING, Z95

__all__ = [
    "confirmed_where_incoherent_note",
    "count_notes",
    "dropped_where_peaks_remain",
    "no_mode_kept_note",
    "not_needed_note",
    "not_picked_note",
    "not_separated_notes",
    "pick_moved_note",
    "pick_notes",
    "reported_as_one_note",
    "unresolved_damping_notes",
]


def no_mode_kept_note(count: ModeCount, modes: pd.DataFrame, band_hz) -> QualityWarning:
    """The ``count_undecided`` note of a count that keeps no mode in ``band_hz`` (Hz): ``modes`` stand."""
    poles = ", ".join(
        f"{f:.3g} Hz (damping {x:.2f})" for f, x in zip(count.model.freq_hz, count.model.damping, strict=True)
    )
    return QualityWarning(
        "count_undecided",
        (),
        f"the maximum-likelihood modal model keeps no mode in {band_hz[0]:.3g}-{band_hz[1]:.3g} Hz (its poles: "
        f"{poles or 'none'}); the {len(modes)} mode(s) of the diagram's selection are reported, unconfirmed by it",
        float(len(modes)),
    )


def pick_notes(count: ModeCount, keep: np.ndarray) -> list[QualityWarning]:
    """What the record says of modes picked by hand: a ``pick_not_supported`` note for each pick
    the count calls ``undecided`` (``keep``: the picked poles it reports, by pole), and a
    ``mode_count`` note when one mode more than the model holds lowers the criterion decisively."""
    decisive = count.settings.decisive_bic
    notes = []
    for i in np.flatnonzero(keep & (count.verdicts() == "undecided")):
        rise, f = float(count.removal_rise[i]), float(count.model.freq_hz[i])
        notes.append(
            QualityWarning(
                "pick_not_supported",
                (),
                f"the record does not support the mode picked at {f:.3f} Hz: without it (the other modes refitted "
                f"free) the information criterion changes by {rise:+.1f}, less than the {decisive:g} a needed "
                "mode raises it; treat it as tentative, or pick another column of the diagram",
                f,
                (f,),
            )
        )
    if count.best_addition > decisive and np.isfinite(count.best_addition_hz):
        f = count.best_addition_hz
        notes.append(
            QualityWarning(
                "mode_count",
                (),
                f"the record holds one mode more than the modal model behind the picks, near {f:.3f} Hz: adding "
                "it lowers "
                f"the information criterion by {count.best_addition:.1f}",
                f,
                (f,),
            )
        )
    return notes


def _why_not_reported(rise_bic: float) -> str:
    if rise_bic > 0:
        return f"the criterion (BIC) rises by {rise_bic:.1f}, so it is not reported"
    return (
        "the search, which splits only the mode nearest the residual's peak, did not try it (with it the "
        f"criterion falls by {-rise_bic:.1f}), so it is not reported"
    )


def _what_to_do(in_diagram: bool) -> str:
    if in_diagram:
        return "pick it (--pick) to see what the record says of it"
    # a split's pole: the ARMAX fits merge it with its neighbour, and a pick takes a diagram's column
    return (
        "the diagram holds no stable column there to pick (its ARMAX fits merge it with a neighbour); a longer "
        "record would decide"
    )


def count_notes(count: ModeCount, keep: np.ndarray, band_hz, same_row_freq: float) -> list[QualityWarning]:
    """Every note of the count, from its steps, verdicts, margins and equally good models.

    Parameters
    ----------
    count : ModeCount
        The count's result.
    keep : (n_poles,) bool ndarray
        The poles reported as modes.
    band_hz : (float, float)
        The band the count decided on, Hz.
    same_row_freq : float
        The relative frequency within which two poles are one mode.

    Returns
    -------
    list of QualityWarning
        What the search did, where the record does not decide, the starts it left out or kept
        unreported, the intervals widened, and the poles that are no modes of the band.
    """
    verdicts = count.verdicts(band_hz)  # each pole's, decided once by the count
    return [
        *_step_notes(count, same_row_freq),
        *_undecided_notes(count, keep, verdicts),
        *_left_out_notes(count),
        *_widened_notes(count, keep, same_row_freq),
        *_stand_in_notes(count, band_hz),
        *_outside_notes(count, verdicts, band_hz),
    ]


def _step_notes(count: ModeCount, same_row_freq: float) -> list[QualityWarning]:
    """One ``mode_count`` note per accepted step of the search."""
    words, notes = {"remove": "left out", "add": "added", "split": "split in two"}, []
    for step in count.steps:
        moved = np.isfinite(step.settled_hz) and abs(np.log(step.settled_hz / step.freq_hz)) > same_row_freq
        where = f" (its new pole settled at {step.settled_hz:.3f} Hz)" if moved else ""
        notes.append(
            QualityWarning(
                "mode_count",
                (),
                f"the mode at {step.freq_hz:.3f} Hz {words[step.action]}{where}: the information criterion (BIC) of "
                f"the maximum-likelihood modal model, every pole free, falls by {step.bic_fall:.1f}",
                float(step.freq_hz),
                (step.freq_hz,),
            )
        )
    return notes


def _undecided_notes(count: ModeCount, keep: np.ndarray, verdicts: np.ndarray) -> list[QualityWarning]:
    """Where the criterion does not decide: a reported mode, one mode more, a mode the likelihood wants."""
    decisive, notes = count.settings.decisive_bic, []
    undecided = keep & (verdicts == "undecided") & (count.removal_rise < decisive)  # reported, the criterion's
    if undecided.any():
        rise = float(count.removal_rise[undecided].min())
        weakest = count.model.freq_hz[np.flatnonzero(undecided)[np.argmin(count.removal_rise[undecided])]]
        notes.append(
            QualityWarning(
                "count_undecided",
                (),
                f"the record does not decide the number of modes: with one mode fewer (the rest refitted free) the "
                f"criterion rises by only {rise:.1f} (under {decisive:g}, Kass & Raftery's 'very strong'); "
                f"treat the weakest mode ({weakest:.3f} Hz) as tentative",
                rise,
                (weakest,),
            )
        )
    if count.best_addition > -decisive and np.isfinite(count.best_addition_hz):
        f = count.best_addition_hz
        notes.append(
            QualityWarning(
                "count_undecided",
                (),
                f"the record does not rule out one mode more (near {f:.3f} Hz): adding it changes the criterion by "
                f"{-count.best_addition:+.1f}, less than {decisive:g} either way",
                f,
                (f,),
            )
        )
    if count.wanted:
        f, ratio, dof, rise_bic, in_diagram = count.wanted  # a Wanted
        notes.append(
            QualityWarning(
                "count_undecided",
                (),
                f"the record may hold one mode more near {f:.3f} Hz: adding it raises the likelihood far beyond chance "
                f"(likelihood ratio {ratio:.1f} for its {dof} parameters, p < "
                f"{count.settings.decisive_alpha:g}) and the "
                f"mode is the same in both halves of the record, but {_why_not_reported(rise_bic)}; "
                f"{_what_to_do(in_diagram)}",
                f,
                (f,),
            )
        )
    return notes


def _left_out_notes(count: ModeCount) -> list[QualityWarning]:
    """The starts the search carried away, and the additions the halves leave unsettled or refuse."""
    notes = []
    for start, went in count.carried_away:
        notes.append(
            QualityWarning(
                "mode_count",
                (),
                f"the free fit carried the starting mode at {start:.3f} Hz to {went:.3f} Hz, where it is no mode (its "
                "damping unresolved, or not the same in both halves of the record); left out",
                went,
                (went,),
            )
        )
    for f in count.unsettled_hz:
        notes.append(
            QualityWarning(
                "count_undecided",
                (),
                f"the mode at {f:.3f} Hz lowers the criterion decisively, but its frequency and damping in the "
                "record's "
                f"two halves differ by more than chance allows at the {100 * count.agreement.alpha:g} % level, "
                "though not "
                f"by enough ({count.settings.decisive_alpha:g}) to call it a change during the record: it is "
                "reported, "
                "tentative; compare another record of the structure",
                f,
                (f,),
            )
        )
    ruled = count.adequacy is not None and not count.adequacy.adequate  # the halves refuse at alpha, not below
    for f in count.unconfirmed_hz:
        why = (
            (
                f"its frequency and damping in the record's two halves differ beyond chance at the "
                f"{100 * count.agreement.alpha:g} % level, which refuses it where the model misfits the record (the "
                "count's rule): a change during the record or a mode the misfit disturbs; left out"
            )
            if ruled
            else (
                "not each of its halves: a change during the record (a drifting frequency, a transient, a "
                "nonlinearity), not a mode; left out"
            )
        )
        notes.append(
            QualityWarning(
                "mode_count", (), f"one mode more near {f:.3f} Hz fits the whole record better but {why}", f, (f,)
            )
        )
    return notes


def _widened_notes(count: ModeCount, keep: np.ndarray, same_row_freq: float) -> list[QualityWarning]:
    """The reported intervals that cover the equally good models' values."""
    widened = [count.model.freq_hz[i] for i in np.flatnonzero(keep) if count.other_structures(i, same_row_freq)[1]]
    if not widened:
        return []
    sizes = ", ".join(f"{alt.n_modes} modes ({d:+.1f})" for d, alt in count.alternatives)
    return [
        QualityWarning(
            "mode_count",
            (),
            f"the 95 % intervals of the mode(s) at {', '.join(f'{f:.3f}' for f in widened)} Hz also cover their values "
            f"in the models the record cannot tell from the chosen one ({sizes} in the criterion): the number of modes "
            "is part of their uncertainty",
            float(len(widened)),
            tuple(widened),
        )
    ]


def _stand_in_notes(count: ModeCount, band_hz) -> list[QualityWarning]:
    """The starts carried where no mode is founded but which the model needs."""
    notes = []
    for start, went, rise_without in count.stand_ins:
        # inside the band, a pole the likelihood needs is the record's own: it does not decide whether a mode
        # is there (a body's 17.40 Hz mode stood there, its halves disagreeing, under 'good')
        inside = band_hz[0] <= went <= band_hz[1]
        notes.append(
            QualityWarning(
                "count_undecided" if inside else "mode_count",
                (),
                f"the free fit carried the starting mode at {start:.3f} Hz to {went:.3f} Hz, where it is no mode (its "
                "damping unresolved, or not the same in both halves of the record), but the model needs it (without it "
                f"the criterion rises by {rise_without:.1f}): it stays in the model, as a pole for what the "
                "record does "
                "not resolve there, and is not reported"
                + (
                    "; whether a mode is there, the record does not decide: compare another record of the "
                    "structure, or "
                    "pick it ('--pick') to see what the record says of it"
                    if inside
                    else ""
                ),
                went,
                (went,),
            )
        )
    return notes


def _outside_notes(count: ModeCount, verdicts: np.ndarray, band_hz) -> list[QualityWarning]:
    """The borderline poles, the modes beyond the band, and the poles that stand for what lies there."""
    notes = [_borderline_note(count.model, i, band_hz) for i in np.flatnonzero(verdicts == "borderline")]
    notes += [_beyond_band_note(count.model, i, band_hz) for i in np.flatnonzero(verdicts == "beyond_band")]
    # what stands for what lies beyond the band, over-damped poles, lines
    outside = ~reported(count.model, band_hz) & ~np.isin(verdicts, ("borderline", "beyond_band"))
    hidden = int(outside.sum())
    if hidden:
        poles = zip(count.model.freq_hz[outside], count.model.damping[outside], strict=True)
        out = ", ".join(f"{f:.3g} Hz (damping {x:.2f})" for f, x in poles)
        notes.append(
            QualityWarning(
                "mode_count",
                (),
                f"{hidden} pole(s) of the modal model lie outside the band {band_hz[0]:.3g}-{band_hz[1]:.3g} Hz, are "
                f"damped beyond {MAX_DAMPING:g} or are lines (damping at the fit's floor): {out}. They stand for "
                "what lies "
                "beyond the band or for a periodic disturbance, and are not reported as modes",
                float(hidden),
                tuple(count.model.freq_hz[outside]),
            )
        )
    return notes


def _pole_and_reach(model, i: int) -> tuple[float, float, float, float]:
    """A pole's frequency and damping and their 95 % intervals' half-widths (what its notes name)."""
    return model.freq_hz[i], model.damping[i], Z95 * model.freq_sd[i], Z95 * model.damping_sd[i]


def _beyond_band_note(model, i: int, band_hz) -> QualityWarning:
    f, x, df, dx = _pole_and_reach(model, i)
    side, edge = ("above", f + df) if f > band_hz[1] else ("below", f - df)
    return QualityWarning(
        "mode_beyond_band",
        (),
        f"the record holds a mode {side} the band {band_hz[0]:.4g}-{band_hz[1]:.4g} Hz: the modal model needs a pole "
        f"at {f:.3f} Hz (95 % interval {f - df:.4g}-{f + df:.4g} Hz), damping {x:.3f} ({x - dx:.3f}-{x + dx:.3f}). "
        f"It is not reported, as it lies outside the band (the input's excited band, or --band within it); to "
        f"report it, excite the structure and fit a band reaching {side.replace('above', 'past')} {edge:.3g} Hz",
        float(f),
        (f,),
    )


def _borderline_note(model, i: int, band_hz) -> QualityWarning:
    f, x, df, dx = _pole_and_reach(model, i)
    where, reach = [], []
    if not band_hz[0] <= f <= band_hz[1]:
        where.append(f"beyond the band {band_hz[0]:.4g}-{band_hz[1]:.4g} Hz")
        reach.append("into the band")
    if x > MAX_DAMPING:
        where.append(f"damped beyond {MAX_DAMPING:g}")
        reach.append(f"below {MAX_DAMPING:g}")
    return QualityWarning(
        "count_undecided",
        (),
        f"the modal model's pole at {f:.3f} Hz (damping {x:.2f}) lies {' and '.join(where)}, so it is not reported "
        f"as a mode, but its 95 % interval ({f - df:.4g}-{f + df:.4g} Hz, damping {x - dx:.2f}-{x + dx:.2f}) reaches "
        f"{' and '.join(reach)}: the record does not decide whether the band holds one mode more there (a heavily "
        "damped mode near the band's edge is estimated so); excite and fit a band reaching past it to decide",
        float(f),
        (f,),
    )


def not_separated_notes(modes: pd.DataFrame) -> list[QualityWarning]:
    """A ``modes_not_separated`` note for each pair of neighbouring modes the record does not
    separate (:func:`~armaxmodal.modes.intervals.not_separated`) and that the count did not report
    as one (picks, or modes the count left)."""
    f = modes.freq_hz.to_numpy()
    return [
        QualityWarning(
            "modes_not_separated",
            (),
            f"modes at {f[i]:.3f} and {f[j]:.3f} Hz are {gap:.1f} standard deviations of their difference apart (the "
            "95 % interval of the difference holds zero): the record does not separate them; they may be one mode",
            float(f[i]),
            (f[i], f[j]),
        )
        for i, j, gap in not_separated(with_intervals(modes))
    ]


def unresolved_damping_notes(modes: pd.DataFrame, n_orders: int) -> list[QualityWarning]:
    """A ``damping_unresolved`` note for every mode whose damping interval spans a factor e^2 or
    more, or reaches critical damping, or whose damping estimate is not positive at some orders of
    the sweep, with the reason. Taken on the logarithm, a damping interval never reaches zero; a
    factor e either side of the value is where the symmetric interval of the same deviation would."""
    notes = []
    for m in modes.itertuples(index=False):
        crossed = int(m.orders_damping_unresolved)
        if crossed == 0 and m.damping_ci95_hi < min(1.0, np.e**2 * m.damping_ci95_lo):
            continue
        facts = [f"damping {m.damping:.2g}, 95 % interval [{m.damping_ci95_lo:.2g}, {m.damping_ci95_hi:.2g}]"]
        if crossed:
            facts.append(f"its estimate is not positive at {crossed} of {n_orders} orders")
        if getattr(m, "model_error_dominates", False):
            why = (
                "the interval is the spread of the record's thirds (model_error_dominates): the thirds disagree "
                "about this damping; run 'armaxmodal diagnose'"
            )
        elif getattr(m, "structure_widened", False) or getattr(m, "estimator_widened", False):
            why = (
                "the interval covers the other models the record finds as good (another number of modes, two poles "
                "reported as one) or the other estimator's value, which disagree about this damping"
            )
        else:
            why = "the damping is below what this record resolves: a longer record, or more excitation here, narrows it"
        notes.append(
            QualityWarning(
                "damping_unresolved",
                (),
                f"mode at {m.freq_hz:.3f} Hz ([{m.freq_ci95_lo:.4g}, {m.freq_ci95_hi:.4g}] Hz): "
                f"{'; '.join(facts)}. {why}",
                float(m.freq_hz),
                (m.freq_hz,),
            )
        )
    return notes


def reported_as_one_note(pair_hz, gap: float, same_shape: float, f: float, x: float) -> QualityWarning:
    """Two poles of the count reported as one mode at ``f`` Hz (damping ``x``): ``gap`` standard
    deviations apart (the 95 % interval of their difference holds zero), their shapes' MAC at least
    ``same_shape``."""
    return QualityWarning(
        "modes_not_separated",
        (),
        f"the modal model needs two poles at {pair_hz[0]:.3f} and {pair_hz[1]:.3f} Hz, but they are {gap:.1f} "
        "standard deviations of their difference apart (its 95 % interval holds zero) and their shapes agree "
        f"(MAC at least {same_shape:g}): the record does not separate them. Reported as one mode at {f:.3f} Hz "
        f"(damping {x:.3g}, the model with one pole there), its intervals covering both: one resonance whose "
        "frequency moves during the record (a nonlinearity, a change) or two modes this record cannot resolve",
        f,
        tuple(pair_hz),
    )


def confirmed_where_incoherent_note(f: float, rise: float) -> QualityWarning:
    """A mode at ``f`` Hz no coherent H1 line tests, confirmed by the modal model (``rise``: the
    criterion's rise without it)."""
    return QualityWarning(
        "mode_count",
        (),
        f"no output's H1 is coherent near {f:.3f} Hz, so the FRF check cannot test that mode; the maximum-likelihood "
        f"modal model, fitted to the record's DFT, confirms it: without it the criterion rises by {rise:.0f}, and "
        "both halves of the record give it the same frequency and damping",
        float(f),
        (f,),
    )


def pick_moved_note(picked_hz: float, f: float, x: float) -> QualityWarning:
    """A pick the modal model takes to ``f`` Hz (damping ``x``), where it is no mode of the band."""
    return QualityWarning(
        "pick_not_supported",
        (),
        f"the maximum-likelihood modal model takes the mode picked at {picked_hz:.3f} Hz to {f:.3f} Hz (damping "
        f"{x:.3g}): beyond the band, damped beyond {MAX_DAMPING:g} or a line. The record does not support a mode "
        "there; it is reported from the diagram's fit, unconfirmed",
        float(picked_hz),
        (picked_hz,),
    )


def not_picked_note(model, others) -> QualityWarning:
    """The modes of ``model`` (indices ``others``) no pick took: kept in the model, not reported."""
    return QualityWarning(
        "mode_count",
        (),
        f"{len(others)} mode(s) of the record were not picked and are not reported: "
        + ", ".join(f"{model.freq_hz[i]:.3f} Hz (damping {model.damping[i]:.3g})" for i in others)
        + "; they stay in the modal model, so that the picked modes' values are not biased by their absence",
        float(len(others)),
        tuple(model.freq_hz[others]),
    )


def dropped_where_peaks_remain(count: ModeCount | None, peaks, same_row_freq: float) -> list[QualityWarning]:
    """A ``count_undecided`` note for each starting mode the count left out as unfounded
    (``count.carried_away``) while the measured FRF keeps a coherent peak that no reported mode
    explains within ``same_row_freq`` of where it started or went (``peaks``: the
    ``unexplained_peak`` notes). The two kinds of evidence disagree: the halves test is weak on a
    transient input (an earthquake's record), and the H1 still shows a resonance there. (A stand-in,
    kept in the model unreported, is undecided already inside the band: :func:`count_notes`.)"""
    if count is None:
        return []
    notes = []
    for start, went, fate in [(start, went, "left out") for start, went in count.carried_away]:
        near = [
            p.value for p in peaks if min(abs(np.log(p.value / start)), abs(np.log(p.value / went))) <= same_row_freq
        ]
        if near:
            notes.append(
                QualityWarning(
                    "count_undecided",
                    (),
                    f"the starting mode at {start:.3f} Hz was {fate} (the free fit took it to {went:.3f} Hz, where it "
                    f"is no mode), but the measured FRF keeps a coherent peak no mode explains at "
                    f"{', '.join(f'{f:.2f}' for f in near)} Hz: the record does not decide whether a mode is there; "
                    "compare another record of the structure, or pick it ('--pick') to see what the record says of it",
                    float(start),
                    (start, *near),
                )
            )
    return notes


def undriven_resonance_note(f: float, n_orders: int, dampings: np.ndarray, peaks) -> QualityWarning:
    """The ``undriven_resonance`` note of :func:`~armaxmodal.modes.frf.undriven_resonances`: a column at
    ``f`` Hz of ``n_orders`` orders whose poles' damping ratios are ``dampings`` (all negative), beside
    the coherent H1 peaks ``peaks`` (``(Hz, sensor, |H1|)``)."""
    peak = max(peaks, key=lambda p: p[2])
    sensors = tuple(sorted({p[1] for p in peaks}))
    return QualityWarning(
        "undriven_resonance",
        sensors,
        f"the measured FRF peaks at {peak[0]:.2f} Hz ({', '.join(sensors)}) where the diagram holds a column at "
        f"{f:.2f} Hz of poles with negative damping ({dampings.min():.3f} to {dampings.max():.3f}) at {n_orders} "
        "orders, and no mode is reported there: the structure resonates at that frequency, but the measured input "
        "does not drive the resonance as it drives a mode of a structure on one moving base (as where other "
        "supports move it through other paths, or the outputs lead the input). "
        f"{f:.2f} Hz is the record's estimate of that mode's frequency; its damping cannot be estimated from this "
        "input",
        f,
        (f,),
    )


def not_needed_note(
    f: float, x: float, neighbour_hz: float | None, level: float, alpha: float, rise: float, p: float
) -> QualityWarning:
    """The mode at ``f`` Hz (damping ``x``) the measured FRF does not need: without it the misfit rises by
    ``rise`` (a share), under ``level`` or not significantly (``p`` above ``alpha``); with ``neighbour_hz``,
    the mode there took the whole peak (a ``split_merged`` note), else a ``mode_not_needed`` one."""
    evidence = (
        f"without it no output's misfit rises by {100 * level:g} % (at most {100 * rise:+.1f} %, p = {p:.2g})"
        if rise < level
        # large enough, but within what chance gives on these lines
        else f"without it an output's misfit rises by {100 * rise:+.1f} %, but not significantly (p = {p:.2g}, "
        f"above {alpha:g})"
    )
    if neighbour_hz is not None:
        return QualityWarning(
            "split_merged",
            (),
            f"modes at {neighbour_hz:.3f} and {f:.3f} Hz overlap within their half-power bands and the measured FRF "
            f"does not need both: {evidence} once {neighbour_hz:.3f} Hz may take the whole peak; one peak split by "
            f"the model, {neighbour_hz:.3f} Hz is reported",
            float(f),
            (neighbour_hz, f),
        )
    return QualityWarning(
        "mode_not_needed",
        (),
        f"a stable pole at {f:.3f} Hz (damping {x:.3f}) is left out: the measured FRF does not need it, {evidence}: "
        "a spurious pole of the model (noise, a nonlinearity, leakage), not a mode of the record",
        float(f),
        (f,),
    )


def rule_notes(count: ModeCount, sensors, without_column=()) -> list[QualityWarning]:
    """Where the counted model misfits the record beyond its noise (``count.adequacy``), the rule the
    count then ran by, in one ``model_inadequate`` note that says what it refused; and a
    ``count_undecided`` note for each reported mode that does not pass it (``without_column``, Hz:
    no stable column of the diagram there). Nothing where the model is adequate.

    Parameters
    ----------
    count : ModeCount
        The count's result.
    sensors : sequence of str
        The outputs, in the order of ``count.adequacy.ratio``.
    without_column : sequence of float
        The reported modes the rule refuses (Hz), as :mod:`armaxmodal.modes.counted` finds them.

    Returns
    -------
    list of QualityWarning
    """
    test = count.adequacy
    if test is None or test.adequate:
        return []
    if np.all(np.isnan(test.ratio)):
        worst, found = 0, "the band holds too few lines to measure the record's noise"
    else:
        worst = int(np.nanargmax(test.ratio))
        found = (
            f"the modal model's residual holds {test.ratio[worst]:.2f} times the record's own noise on "
            f"'{sensors[worst]}' (at most {test.level:g} where a model explains the record)"
        )
    text = (
        f"{found}: the criterion, which assumes a right model, cannot count the modes alone, so a mode the "
        "count adds must also stand in a stable column of the diagram"
    )
    if count.rule_refused:
        fall, freqs = count.rule_refused
        text += (
            f"; the criterion alone chose {len(freqs)} modes ({', '.join(f'{f:.2f}' for f in freqs)} Hz, lower "
            f"by {fall:.1f}), refused by that rule"
        )
    notes = [QualityWarning("model_inadequate", (sensors[worst],), text, float(test.ratio[worst]))]
    for f in without_column:
        notes.append(
            QualityWarning(
                "count_undecided",
                (),
                f"the mode at {f:.3f} Hz stands in no stable column of the diagram, which the count's rule asks of a "
                "mode where the model misfits the record: treat it as tentative",
                float(f),
                (float(f),),
            )
        )
    return notes
