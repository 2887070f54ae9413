"""Data-quality checks run before any fit: facts with a number, never guesses.

Each check returns :class:`~armaxmodal.QualityWarning` records (a code from ``WARNING_CODES``, the
channels concerned, a sentence with the measured number). The checks need nothing but the
recording:

* ``duplicate_channel`` -- an output equal or proportional to another output or to the
  input (correlation within ``1e-6`` of +-1): an exported-twice channel adds no information
  and, pooled, gives zero-width intervals.
* ``inverted_sensor`` / ``sensor_delay`` -- :mod:`armaxmodal.prepare.delay`.
* ``narrowband_input`` -- the input's power sits in a narrow band (a sine ride): modes
  outside it rest on the input's weaker content (the shake-table sine rides still give the
  broadband rides' modes), so the modal-model check's coherent lines decide.
* ``clipping`` -- samples piled up at a channel's extreme value (the sensor's rail): more
  than the values just inside it occur (Poisson; a looser p when two are in a row).
* ``stuck_samples`` -- a run of equal samples elsewhere, longer than the channel's own rate
  of repeated samples makes likely: a sensor or a recorder that stopped updating.
* ``incoherent_output`` -- an output whose coherence with the input, averaged over the
  input's spectrum and over its own, is below ``INCOHERENT``: it is not a response to this
  input (a wrong column, a dead sensor, a second excitation), and its poles are not the structure's. A
  record of pure noise once gave two "modes" with intervals and no warning.
* ``unit_mismatch`` -- an output in other units than the rest, or every output in other
  units than the input (:mod:`armaxmodal.prepare.units`).
* ``held_samples`` -- a channel sampled at a lower rate and held to the record's
  (:mod:`armaxmodal.prepare.held`): its repeats keep to a cycle.

The sweep adds ``periodic_disturbance`` (``disturbance_lines`` in :mod:`armaxmodal.modes.poles`); preparation
(:mod:`armaxmodal.prepare.preparation`) adds ``offset_removed``, ``offset_step``, ``drift``,
``trend_removed`` and ``resampled``.
"""

from __future__ import annotations

import numpy as np

from armaxmodal.quality_warnings import QualityWarning, not_run
from armaxmodal.recording import Recording
from armaxmodal.spectra import coherence, welch_spectra
from armaxmodal.stats import welch_nperseg

__all__ = [
    "CLIP_MIN_SAMPLES",
    "INCOHERENT",
    "NEIGHBOUR_LEVELS",
    "STUCK_EDGE_MIN",
    "STUCK_MIN_RUN",
    "clipped_channels",
    "duplicate_channels",
    "incoherent_outputs",
    "input_coherence",
    "narrowband_input",
    "rail_pileup",
    "stuck_channels",
    "stuck_runs",
]

#: An output less coherent with the input than this (averaged over the input's spectrum, and
#: over the output's own) is not its response: response sensors read 0.63-1.00 on the measured
#: records (the F-16, the shake-table IMUs' Northridge and sine rides) and 0.68-1.00 on the
#: fixtures; independent noise about 0.07 (the estimate's bias with 15 segments).
INCOHERENT = 0.3

#: |correlation| above 1 - this is a copy: two physical sensors never agree this well
#: (16-bit quantisation of a proportional copy leaves ~1e-9).
DUPLICATE_TOLERANCE = 1e-6
#: Shortest run of equal samples tested (two in a row happen on any quantised channel).
STUCK_MIN_RUN = 3
#: family-wise level of the stuck-samples warning over the channels
STUCK_ALPHA = 0.01
#: a run at the record's first or last sample shorter than this is padding (a channel
#: shifted into alignment repeats its first value a few times), not a dropout: not reported
STUCK_EDGE_MIN = 10
#: the input is narrowband when the lines within 10 dB of its PSD peak span less than this
#: fraction of the peak frequency (a sine ride: a few lines; the sine sweep and random rides
#: of the fixtures: 0.7-3.7; an earthquake record: 0.85-2.9)
NARROWBAND_FRACTION = 0.3
#: samples at the extreme values that make a channel clipped, when their pile-up is beyond
#: the channel's own distribution (CLIP_PILEUP_P; CLIP_HELD_P with two in a row)
CLIP_MIN_SAMPLES = 5
#: Distinct values inside a rail whose counts give the expected count at the rail.
NEIGHBOUR_LEVELS = 5
#: Poisson p of a rail's count (against its neighbours') below which the rail is a pile-up
#: (two rails on a handful of channels: about 1e-3 family-wise). A record sampled a few times
#: per period clips each peak in one sample, never two in a row (the supine ride's head
#: clipped at 60 % of its peak: 71 samples, none adjacent, p 6e-54); continuous data: p = 1
CLIP_PILEUP_P = 1e-4
#: the same p for a rail held two samples in a row (stronger evidence than the count alone)
CLIP_HELD_P = 0.01


def input_coherence(u: np.ndarray, y: np.ndarray, fs: float) -> np.ndarray:
    """Each output's magnitude-squared coherence with the input (Welch, 10 s segments at most
    an eighth of the record), averaged with the input's power as weight: the share of the
    output, at the frequencies the input drives, that a linear response to it explains, (K,)."""
    y = np.asarray(y, float).reshape(len(u), -1)
    _, puu, puy, pyy = welch_spectra(u, y, fs, welch_nperseg(len(u), fs))
    return _power_weighted(puu, coherence(puu, puy, pyy))


def _power_weighted(power: np.ndarray, coh: np.ndarray) -> np.ndarray:
    """Each output's coherence averaged with ``power`` as weight: one spectrum for every output
    (the input's, (n_freq,)) or one per output (their own, (n_freq, K)); (K,)."""
    w = power if power.ndim == coh.ndim else power[:, None]
    return np.sum(w * coh, axis=0) / np.maximum(np.sum(w, axis=0), 1e-300)


def incoherent_outputs(recording: Recording) -> list[QualityWarning]:
    """Outputs whose coherence with the input is below ``INCOHERENT`` both averaged over the
    input's spectrum (:func:`input_coherence`) and over the output's own: the share of its power
    the input explains. The second keeps a lightly damped structure's sensor: it moves at its
    resonances and barely elsewhere, so over most of the input's band its noise floor dominates (a
    1 %-damped chain's top sensors read 0.21 and 0.28 over the input's spectrum, far above 0.3 over
    their own, and dropping them lost a mode)."""
    if recording.n_samples < 128:
        return [not_run("incoherent_output", recording.sensors, f"{recording.n_samples} samples, fewer than 128")]
    _, puu, puy, pyy = recording.welch(welch_nperseg(recording.n_samples, recording.fs))  # the record's own
    coh = coherence(puu, puy, pyy)
    levels = _power_weighted(puu, coh)
    own = _power_weighted(pyy, coh)
    low = [
        (name, float(c))
        for name, c, o in zip(recording.sensors, levels, own, strict=True)
        if c < INCOHERENT and o < INCOHERENT
    ]
    if not low:
        return []
    every = len(low) == len(recording.sensors)
    return [
        QualityWarning(
            "incoherent_output",
            tuple(name for name, _ in low),
            "coherence with the input '"
            + recording.input_name
            + "', averaged over its spectrum: "
            + ", ".join(f"{name} {c:.2f}" for name, c in low)
            + (
                ". No output responds to this input: the modes found are not the structure's; check the "
                "input and output columns."
                if every
                else ". These outputs do not respond to this input (a wrong column, a dead sensor, a second "
                "excitation, a logger whose clock drifts against the input's); their poles are not the structure's."
            ),
            min(c for _, c in low),
        )
    ]


def duplicate_channels(recording: Recording) -> list[QualityWarning]:
    """Outputs equal or proportional to an earlier output or to the input."""
    names = [recording.input_name, *recording.sensors]
    data = np.column_stack([recording.base, recording.response])
    data = data - data.mean(axis=0)
    norms = np.linalg.norm(data, axis=0)
    found, taken = [], set()
    for j in range(1, len(names)):
        if norms[j] == 0:
            continue
        for i in range(j):
            if i in taken or norms[i] == 0:
                continue
            r = float(data[:, i] @ data[:, j] / (norms[i] * norms[j]))
            gap = max(0.0, 1 - abs(r))
            if gap <= DUPLICATE_TOLERANCE:
                ratio = float(data[:, j] @ data[:, i] / norms[i] ** 2)
                kind = "the input" if i == 0 else f"output '{names[i]}'"
                how = "a copy of" if abs(ratio - 1) < 1e-9 else f"{ratio:.6g} times"
                found.append(
                    QualityWarning(
                        "duplicate_channel",
                        (names[j], names[i]),
                        f"output '{names[j]}' is {how} {kind} (1 - |correlation| = {gap:.1e}): a copy carries "
                        "no information of its own and was left out of the fit.",
                        gap,
                    )
                )
                taken.add(j)
                break
    return found


def narrowband_input(recording: Recording) -> list[QualityWarning]:
    """The width of the lines within 10 dB of the input's PSD peak against the peak frequency."""
    n = recording.n_samples
    nperseg = welch_nperseg(n, recording.fs, seconds=20.0, max_fraction=4)
    if nperseg < 16:
        return [not_run("narrowband_input", (recording.input_name,), f"{n} samples, too few for the input's spectrum")]
    f, puu, _, _ = recording.welch(nperseg)
    peak = float(f[int(np.argmax(puu))])
    live = puu >= 0.1 * puu.max()
    width = float(np.count_nonzero(live) * (f[1] - f[0]))
    if peak <= 0 or width >= NARROWBAND_FRACTION * peak:
        return []
    return [
        QualityWarning(
            "narrowband_input",
            (recording.input_name,),
            f"the input's power within 10 dB of its peak covers {width:.2f} Hz around {peak:.2f} Hz "
            f"({f[live].min():.2f}-{f[live].max():.2f} Hz): a sine-like ride. Modes away from it rest on the "
            "input's weaker content; the modal-model check marks a mode no coherent H1 line confirms as "
            "unconfirmed (quality: poor).",
            width,
        )
    ]


def rail_pileup(x: np.ndarray) -> list[tuple[float, int, float, float]]:
    """Each rail's ``(value, count, expected count, p)`` for the maximum and the minimum of ``x``.

    ``expected`` is the mean count of the ``NEIGHBOUR_LEVELS`` distinct values next inside the
    rail; ``p = P(N >= count)`` for ``N`` Poisson with that mean.
    """
    from scipy.special import pdtrc

    values, counts = np.unique(x, return_counts=True)
    out = []
    for rail, inner in ((-1, counts[-1 - NEIGHBOUR_LEVELS : -1]), (0, counts[1 : 1 + NEIGHBOUR_LEVELS])):
        count = int(counts[rail])
        expected = float(np.mean(inner)) if inner.size else 1.0
        p = float(pdtrc(count - 1, expected)) if count > 1 else 1.0  # P(N >= count)
        out.append((float(values[rail]), count, expected, p))
    return out


def clipped_channels(recording: Recording) -> list[QualityWarning]:
    """Channels piled up on their maximum or minimum (the rail of a sensor or recorder): at
    least ``CLIP_MIN_SAMPLES`` there, more than the values just inside allow
    (:func:`rail_pileup`, p below ``CLIP_PILEUP_P``, or ``CLIP_HELD_P`` when two are in a row:
    a continuous signal does not dwell on its peak)."""
    found = []
    names = [recording.input_name, *recording.sensors]
    for name, x in zip(names, np.column_stack([recording.base, recording.response]).T, strict=True):
        rails = rail_pileup(x)
        stuck = sum(count for _, count, _, _ in rails)
        held = any(bool(np.any((x[1:] == value) & (x[:-1] == value))) for value, *_ in rails)
        _, count, inside, p = min(rails, key=lambda rail: rail[3])
        # a coarse quantiser dwells on its extreme level too, as often as on the levels inside
        if stuck < CLIP_MIN_SAMPLES or not (p < CLIP_PILEUP_P or (held and p < CLIP_HELD_P)):
            continue
        evidence = f"{count} on one, where the values just inside it occur about {inside:.1f} times each (p = {p:.1e})"
        evidence = "some in a row" if held else evidence
        found.append(
            QualityWarning(
                "clipping",
                (name,),
                f"'{name}' sits at its extreme values for {stuck} samples ({100 * stuck / x.size:.2f} %), "
                f"{evidence}: the sensor or its recorder clipped; the peaks there are lost.",
                100 * stuck / x.size,
            )
        )
    return found


def stuck_runs(x: np.ndarray) -> list[tuple[int, int, float]]:
    """Runs of ``STUCK_MIN_RUN`` or more equal samples away from the extremes:
    ``(first, stop, p)`` each, ``x[first:stop]`` equal, ``p = min(1, n r^(L-1))``."""
    n = x.size
    same = np.concatenate([[False], x[1:] == x[:-1]])
    edges = np.flatnonzero(np.diff(np.concatenate([[0], same.astype(np.int8), [0]])))
    repeats = int(same.sum())
    out = []
    for start, stop in zip(edges[::2], edges[1::2], strict=True):
        first, length = start - 1, stop - start + 1  # the run's first sample is not a repeat
        if length < STUCK_MIN_RUN or x[first] in (x.max(), x.min()):
            continue
        rate = (repeats - (length - 1) + 1) / (n + 1)
        out.append((int(first), int(stop), float(min(1.0, n * rate ** (length - 1)))))
    return out


def stuck_channels(recording: Recording) -> list[QualityWarning]:
    """``stuck_samples``: runs of equal samples away from the channel's extremes (those are
    :func:`clipped_channels`'), longer than the channel's own rate of repeated samples makes
    likely (:func:`stuck_runs`, family-wise STUCK_ALPHA over the channels): a sensor or a
    recorder that stopped updating."""
    names = (recording.input_name, *recording.sensors)
    data = np.column_stack([recording.base, recording.response])
    found = []
    for k, name in enumerate(names):
        runs = [
            r
            for r in stuck_runs(data[:, k])
            if r[2] < STUCK_ALPHA / len(names) and (0 < r[0] and r[1] < len(data) or r[1] - r[0] >= STUCK_EDGE_MIN)
        ]
        if not runs:
            continue
        first, stop, p = max(runs, key=lambda r: r[1] - r[0])
        total = sum(b - a for a, b, _ in runs)
        repeats = float(np.mean(data[1:, k] == data[:-1, k]))
        more = f"; {len(runs)} such runs, {total} samples in all" if len(runs) > 1 else ""
        found.append(
            QualityWarning(
                "stuck_samples",
                (name,),
                f"'{name}' holds {data[first, k]:.6g} for {stop - first} samples in a row from "
                f"{first / recording.fs:.3f} s (p = {p:.1e} against its rate of repeated samples, "
                f"{100 * repeats:.2g} %){more}: the sensor or its recorder stopped updating. The fit takes those "
                "samples as measured; 'armaxmodal diagnose' fills them by prediction.",
                float(total),
            )
        )
    return found
