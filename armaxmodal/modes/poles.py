"""The pole table of a sweep and its rules (thesis Section 3.3.2), and the lines among its poles.

One row per pole of every fit (``pole_rows``), its stability class against the nearest
pole of the previous order of the same source (``stability_classes``: ``new``, ``f``,
``f+d``, ``f+d+v``) and the reason it is rejected, if any (``rejection_reasons``). The
thresholds are the :class:`Tolerances`.

**Periodic disturbances** (``disturbance_lines``): undamped poles the input does not drive. A
sinusoid in an output that the base does not cause (mains hum on a cable, a rotating machine
nearby) is, to an ARMAX model, a pole pair on the unit circle in the disturbance model: the
shared A takes it at every order high enough, with a damping of order 1e-4 and a residue the
input hardly excites (the sweep rejects such poles as "negligible residue", so the modes never
show it). That pattern is the fact reported; no structural mode of the measured records comes
near it (their lightest damping: 0.48 %, the F-16's torsion mode). ``armaxmodal diagnose`` then
names the line, fits it and refits.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from armaxmodal.estimate.result import ArmaxFit
from armaxmodal.modal import mac
from armaxmodal.modes.settings import DEFAULTS, LineSettings
from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.recording import Recording
from armaxmodal.spectra import excited_band
from armaxmodal.stats import MAX_DAMPING, Z95

__all__ = [
    "Tolerances",
    "pole_rows",
    "stability_classes",
    "rejection_reasons",
    "POLE_COLUMNS",
    "borderline",
    "disturbance_lines",
    "physical",
    "reported",
    "resolved",
]

SHARED = "shared"


CLASSES = ("new", "f", "f+d", "f+d+v")


#: rejection reason of a pole whose damping estimate is not positive but whose 95 % interval
#: reaches above zero: a lightly damped mode the record cannot resolve in damping. Such poles
#: count towards a mode's support, never as its estimate (see :func:`select_modes`).
UNRESOLVED_DAMPING = "damping not resolved"
#: ... and negative beyond its interval: a pole that grows (``frf.undriven_resonances`` reads their columns)
NEGATIVE_DAMPING = "negative damping"


@dataclass(frozen=True)
class Tolerances:
    """Stability tolerances between consecutive orders and the pole-rejection rules.

    See Also
    --------
    armaxmodal.stabilisation_diagram : Marks each pole's stability with them.

    Examples
    --------
    >>> from armaxmodal.modes import Tolerances
    >>> tol = Tolerances(freq=0.02)  # a pole is stable in frequency within 2 % of the previous order's
    >>> tol.freq, tol.damping, tol.shape
    (0.02, 0.05, 0.02)
    """

    freq: float = 0.01  #: relative frequency change
    damping: float = 0.05  #: relative damping change
    shape: float = 0.02  #: 1 - MAC for shared shapes; relative residue change per sensor
    min_freq_hz: float | None = None  #: default: 3 / record length
    max_freq_fraction: float = 0.45  #: of fs; poles near Nyquist are filter artefacts
    min_energy: float = 0.01  #: residue energy relative to the largest pole at that order (lower it
    #: to keep weakly excited modes; 0.1 % admits weak extra poles on real and band-limited data)
    min_input_db: float = -30.0  #: input PSD below this (dB re its peak): no excitation there


POLE_COLUMNS = [
    "source",
    "na",
    "freq_hz",
    "damping",
    "damped_freq_hz",
    "freq_sd",
    "damping_sd",
    "freq_ci95_lo",
    "freq_ci95_hi",
    "damping_ci95_lo",
    "damping_ci95_hi",
    "energy",
    "pole",
    "vector",
]


def pole_rows(fit: ArmaxFit, source: str) -> list[dict]:
    """Rows for one fit: shared fit -> one source with shapes over sensors."""
    rows = []
    if source == SHARED:
        table = fit.modes()
        frame = table[table.sensor == fit.sensors[0]]  # not query(): sensor names are free text
        mu = frame.pole.to_numpy()
        shapes = np.array([m.modal_constants(mu)[0] for m in fit.models]) if mu.size else np.zeros((0, 0))
        for i, r in enumerate(frame.itertuples(index=False)):
            rows.append(_row(source, fit, r, shapes[:, i], float(np.linalg.norm(shapes[:, i] * r.freq_hz))))
        return rows
    frame = fit.modes()
    mu = frame.pole.to_numpy()
    consts = fit.models[0].modal_constants(mu)[0] if mu.size else np.zeros(0)
    for i, r in enumerate(frame.itertuples(index=False)):
        rows.append(_row(source, fit, r, np.array([consts[i]]), float(abs(consts[i]) * r.freq_hz)))
    return rows


def _row(source, fit, r, shape, energy):
    return {
        "source": source,
        "na": fit.orders[0],
        "freq_hz": r.freq_hz,
        "damping": r.damping,
        "damped_freq_hz": r.damped_freq_hz,
        "freq_sd": r.freq_sd,
        "damping_sd": r.damping_sd,
        "freq_ci95_lo": r.freq_ci95_lo,
        "freq_ci95_hi": r.freq_ci95_hi,
        "damping_ci95_lo": r.damping_ci95_lo,
        "damping_ci95_hi": r.damping_ci95_hi,
        "energy": energy,
        "pole": r.pole,
        "vector": shape,
    }


def stability_classes(poles: pd.DataFrame, tol: Tolerances) -> list[str]:
    cls = ["new"] * len(poles)
    for _source, group in poles.groupby("source", sort=False):
        by_order = {na: g for na, g in group.groupby("na")}
        nas = sorted(by_order)
        for prev, cur in zip(nas[:-1], nas[1:], strict=True):
            p = by_order[prev]
            for idx, row in by_order[cur].iterrows():
                rel = np.abs(p.freq_hz.values - row.freq_hz) / row.freq_hz
                j = int(np.argmin(rel))
                if rel[j] > tol.freq:
                    continue
                label = "f"
                prev_row = p.iloc[j]
                if abs(prev_row.damping - row.damping) <= tol.damping * max(abs(row.damping), 1e-3):
                    label = "f+d"
                    if row.vector.size > 1:
                        same_shape = 1 - mac(row.vector, prev_row.vector) <= tol.shape
                    else:
                        same_shape = abs(abs(row.vector[0]) / max(abs(prev_row.vector[0]), 1e-300) - 1) <= 5 * tol.shape
                    if same_shape:
                        label = "f+d+v"
                cls[poles.index.get_loc(idx)] = label
    return cls


def rejection_reasons(
    poles: pd.DataFrame, tol: Tolerances, recording: Recording, max_damping: float = MAX_DAMPING
) -> list[str]:
    """Why each pole is not a mode candidate (``""``: it is). Damped beyond ``max_damping`` is
    over-damped: by default the one bound every stage reads (``armaxmodal.stats.MAX_DAMPING``)."""
    f_min = tol.min_freq_hz if tol.min_freq_hz is not None else 3.0 / recording.duration
    f_max = tol.max_freq_fraction * recording.fs
    band_lo, band_hi = excited_band(recording, tol.min_input_db)
    top = poles.groupby(["source", "na"]).energy.transform("max")
    reasons = []
    for row, e_max in zip(poles.itertuples(index=False), top, strict=True):
        if row.damping <= 0:
            sd = getattr(row, "damping_sd", 0.0)
            reasons.append(UNRESOLVED_DAMPING if row.damping + Z95 * sd > 0 else NEGATIVE_DAMPING)
        elif row.damping > max_damping:
            reasons.append("over-damped")
        elif row.freq_hz < f_min:
            reasons.append("near 0 Hz")
        elif row.freq_hz > f_max:
            reasons.append("near Nyquist")
        elif row.freq_hz > band_hi * (1 + row.damping) or row.freq_hz < band_lo * (1 - row.damping):
            reasons.append("no input energy")
        elif row.energy < tol.min_energy * e_max:
            reasons.append("negligible residue")
        else:
            reasons.append("")
    return reasons


def disturbance_lines(
    poles: pd.DataFrame,
    min_energy: float,
    recording: Recording,
    shared: str = "shared",
    min_support: float = 0.4,
    lines: LineSettings = DEFAULTS.lines,
) -> list[QualityWarning]:
    """One ``periodic_disturbance`` warning per line of the shared-pole sweep.

    Parameters
    ----------
    poles : DataFrame
        The diagram's pole table (columns ``source``, ``na``, ``freq_hz``, ``damping``,
        ``energy``).
    min_energy : float
        Residue energy, relative to the strongest pole of the same fit, below which the
        input does not drive a pole (the diagram's ``Tolerances.min_energy``).
    recording : Recording
        The record the sweep fitted: whether its input carries the line too.
    shared : str
        The ``source`` of the shared-pole fits; every other source is one sensor's sweep.
    min_support : float
        Share of the swept orders at which the line must appear (as for a mode).
    lines : LineSettings
        What a line is: damped below ``lines.undamped``, its poles within ``lines.freq_tol``.

    Returns
    -------
    list of QualityWarning
        Each with the line's frequency (Hz) as ``value`` and, as channels, the sensors whose
        own sweep shows it.
    """
    pooled = poles[poles.source == shared]
    n_orders = pooled.na.nunique()
    strongest = pooled.groupby("na").energy.transform("max")
    undriven = pooled[(pooled.damping.abs() < lines.undamped) & (pooled.energy < min_energy * strongest)]
    single = poles[(poles.source != shared) & (poles.damping.abs() < lines.undamped)]
    warnings = []
    for members in _groups(undriven.freq_hz.to_numpy(), lines.freq_tol):
        line = undriven.iloc[members]
        count = line.na.nunique()
        if count < max(3, min_support * n_orders):
            continue
        freq = float(np.median(line.freq_hz))
        near = np.abs(single.freq_hz.to_numpy() / freq - 1) < lines.freq_tol
        channels = tuple(dict.fromkeys(single.source[near]))
        seen = f"sensors whose own sweep shows it: {', '.join(channels)}" if channels else "no sensor alone shows it"
        prominence = _input_prominence(recording, freq)
        if prominence >= lines.input_ratio:
            what = "a line on the input sensor or on every channel (electrical pickup)"
            level = f"{10 * np.log10(prominence):.0f} dB above its neighbouring lines"
            why = f": the input carries the line too ({level}) but the outputs do not follow it as a response"
        else:
            what, why = "a periodic disturbance in the outputs (mains hum, a rotating machine, a harmonic)", ""
        warnings.append(
            QualityWarning(
                "periodic_disturbance",
                channels,
                # the finding first: the terminal shows a note's first clauses
                f"{what} at {freq:.3f} Hz, not a mode; {seen}: a pole with damping at most "
                f"{float(line.damping.abs().max()):.1e} (undamped) at {count} of {n_orders} orders, which the "
                f"input does not drive (residue under {100 * min_energy:g} % of the strongest pole's){why}. The "
                "modes near it were fitted with it in the data: run 'armaxmodal diagnose', which fits the line and "
                "refits.",
                freq,
                (freq,),
            )
        )
    return warnings


def _input_prominence(recording: Recording, freq: float) -> float:
    """The input's PSD at ``freq`` (the largest of the three lines nearest: a line between
    two bins splits its power) over the median of the 20 lines around them, at a resolution
    of a quarter of the record (a line's PSD grows with the segment; the noise's does not)."""
    nperseg = 2 ** int(np.log2(max(recording.n_samples // 4, 16)))
    f, puu, _, _ = recording.welch(nperseg)
    i = int(np.argmin(np.abs(f - freq)))
    around = np.r_[puu[max(i - 12, 0) : max(i - 2, 0)], puu[i + 3 : i + 13]]
    peak = float(puu[max(i - 1, 0) : i + 2].max())
    if peak <= 0:  # no input at all there (a synthetic band-limited ride outside its band)
        return 0.0
    return peak / float(np.median(around)) if around.size and np.median(around) > 0 else np.inf


def _groups(freqs: np.ndarray, tol: float) -> list[list[int]]:
    """Indices of ``freqs`` grouped by relative distance below ``tol`` (in order)."""
    order = np.argsort(freqs)
    groups: list[list[int]] = []
    for i in order:
        if groups and freqs[i] / freqs[groups[-1][-1]] - 1 < tol:
            groups[-1].append(int(i))
        else:
            groups.append([int(i)])
    return groups


def at_fit_floor(model) -> np.ndarray:
    """Which of a model's poles sit at its fit's damping floor (within twice the lowest damping the
    fit allowed): a line or a frequency that moves, not a mode (bool per pole). The supine ride's
    0.3 m/s^2 hum at 12.5 Hz came out at 12.500 Hz, damping 1e-4. The count has no residue-energy
    test, so it cannot take ``LineSettings.undamped``, which would drop the driven light modes."""
    return model.damping <= 2 * model.damping_floor


def reported(model, band_hz) -> np.ndarray:
    """Which of a model's poles are modes of the band (bool per pole): not beyond it, not damped
    beyond ``MAX_DAMPING``, and not a line (``at_fit_floor``)."""
    f, x = model.freq_hz, model.damping
    return (f >= band_hz[0]) & (f <= band_hz[1]) & (x <= MAX_DAMPING) & ~at_fit_floor(model)


def borderline(model, band_hz) -> np.ndarray:
    """Which of a model's poles are not modes of the band by their estimates (beyond it, or damped
    beyond ``MAX_DAMPING``) but are by their 95 % intervals, which reach into the band and below
    ``MAX_DAMPING`` (bool per pole; lines excluded; an interval not known reaches). The record does
    not decide whether a mode of the band stands there: a heavily damped mode near the band's top
    comes out just past it (unseen bodies with feet: 26.4 Hz, damping 0.33, estimated at 28.07 Hz
    in a band ending at 28.06; 26.8 Hz, 0.51, estimated damped 0.63 +- 0.11). A pole held at a bound
    of the fit (``at_bound``) has no Wald interval and is none: it stands for what lies beyond the band
    (a drifting record's two poles at half its lowest line, damping 0.95, "reached" -0.01 to 0.02 Hz)."""
    f, x = model.freq_hz, model.damping
    df, dx = Z95 * model.freq_sd, Z95 * model.damping_sd
    decided_out = (f + df < band_hz[0]) | (f - df > band_hz[1]) | (x - dx > MAX_DAMPING)
    pinned = np.zeros(f.shape, bool) if model.at_bound is None else model.at_bound
    return ~decided_out & ~pinned & ~reported(model, band_hz) & ~at_fit_floor(model)


def beyond_band(model, band_hz) -> np.ndarray:
    """Which of a model's poles are modes the record determines outside the band (bool per pole):
    the 95 % interval of the frequency wholly beyond the band and below the model's Nyquist bound
    (a pole held at that bound has no Wald interval), the damping at most ``MAX_DAMPING`` (as for a
    mode of the band) and resolved (its interval above zero), not a line; an interval not known
    decides nothing. Its resonance, the
    half-power band f(1 -+ damping), must reach into the band: the band's lines then hold its peak's
    flank, which places it, while a pole farther out sees only the band's stiffness-line tail and
    stands for all that lies there. A body's 27.71 Hz mode (damping 0.42) under a ride to 24 Hz, the
    band ending at 25.7 Hz, comes out at 27.5-28.4 Hz, +- 0.35 Hz, damping 0.40-0.44."""
    f, x = model.freq_hz, model.damping
    df, dx = Z95 * model.freq_sd, Z95 * model.damping_sd
    above = (f - df > band_hz[1]) & (f + df < model.nyquist_hz) & (f * (1 - x) < band_hz[1])
    below = (f + df < band_hz[0]) & (f * (1 + x) > band_hz[0])
    return (above | below) & (x - dx > 0) & (x <= MAX_DAMPING) & ~at_fit_floor(model)


def physical(model, band_hz) -> np.ndarray:
    """Per pole of a modal model: in the band (Hz) and damped as a vibration mode can be."""
    return (model.freq_hz >= band_hz[0]) & (model.freq_hz <= band_hz[1]) & (model.damping <= MAX_DAMPING)


def resolved(model, band_hz) -> bool:
    """Every pole of ``model`` in the band is a mode with a damping the record resolves (its
    symmetric 95 % interval above zero): a pole at the damping floor is a line, not a mode."""
    if model is None:
        return False
    shown = physical(model, band_hz)
    return bool(np.all(model.damping[shown] - Z95 * model.damping_sd[shown] > 0))
