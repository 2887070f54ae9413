"""Periodic disturbances the sweep sees: undamped poles the input does not drive.

A sinusoid in an output that the base does not cause (mains hum on a cable, a rotating
machine nearby) is, to an ARMAX model, a pole pair on the unit circle in the disturbance
model: the shared A takes it at every order high enough, with a damping of order 1e-4 and a
residue the input hardly excites (the sweep rejects such poles as "negligible residue", so
the modes never show it). That pattern is the fact reported here; no structural mode of the
measured records comes near it (their lightest damping: 0.48 %, the F-16's torsion mode).
``armaxmodal diagnose`` then names the line, fits it and refits.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from armaxmodal.modes.settings import DEFAULTS, LineSettings
from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.recording import Recording

__all__ = ["disturbance_lines"]


def disturbance_lines(
    poles: pd.DataFrame, min_energy: float, recording: Recording, shared: str = "shared", min_support: float = 0.4,
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
            where = (
                f"the input carries the line too ({10 * np.log10(prominence):.0f} dB above its neighbouring lines) "
                "but the outputs do not follow it as a response: a disturbance on the input sensor, or on every "
                "channel (electrical pickup)"
            )
        else:
            where = (
                "a periodic disturbance in the outputs (mains hum, a rotating machine, a harmonic the input does "
                "not carry)"
            )
        warnings.append(
            QualityWarning(
                "periodic_disturbance",
                channels,
                f"a pole at {freq:.3f} Hz with damping at most {float(line.damping.abs().max()):.1e} (undamped) at "
                f"{count} of {n_orders} orders, which the input does not drive (residue under "
                f"{100 * min_energy:g} % of the strongest pole's): {where}, not a mode; {seen}. The modes near it "
                "were fitted with it in the data: run 'armaxmodal diagnose', which fits the line and refits.",
                freq,
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
