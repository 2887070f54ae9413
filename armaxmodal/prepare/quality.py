"""Data-quality checks run before any fit: facts with a number, never guesses.

Each check returns :class:`QualityWarning` records (a code from :data:`WARNING_CODES`, the
channels concerned, a sentence with the measured number). The checks need nothing but the
recording:

* ``duplicate_channel`` -- an output equal or proportional to another output or to the
  input (correlation within ``1e-6`` of +-1): an exported-twice channel adds no information
  and, pooled, gives zero-width intervals.
* ``inverted_sensor`` / ``sensor_delay`` -- below the first mode a base-excited structure
  moves with its base: the absolute-acceleration transmissibility is ``1 + O(w^2)`` with a
  phase of order ``w^3`` (``T = 1 - w^2 K^-1 M e + ...``). A low-frequency ``T`` near -1 is a
  sensor mounted or exported upside down; a phase that grows *linearly* with frequency is a
  time offset, ``phase = -w tau``. The slope is fitted with the cubic term over the
  quasi-static lines, weighted by the H1 phase variance (Bendat & Piersol 9.2.4).
  Recordings whose low-frequency transmissibility is not near +-1 (a force input, no
  quasi-static band) are not tested, and the check says nothing.
* ``narrowband_input`` -- the input's power sits in a narrow band (a sine ride): modes
  outside it rest on the input's weaker content (the shake-table sine rides still give the
  broadband rides' modes), so the modal-model check's coherent lines decide.
* ``clipping`` -- samples piled up at a channel's extreme value (the sensor's rail): more
  than the values just inside it occur (Poisson; a looser p when two are in a row).
* ``stuck_samples`` -- a run of equal samples elsewhere, longer than the channel's own rate
  of repeated samples makes likely: a sensor or a recorder that stopped updating.
* ``incoherent_output`` -- an output whose coherence with the input, averaged over the
  input's spectrum, is below ``INCOHERENT``: it is not a response to this input (a wrong
  column, a dead sensor, a second excitation), and its poles are not the structure's. A
  record of pure noise once gave two "modes" with intervals and no warning.
* ``unit_mismatch`` -- an output in other units than the rest, or every output in other
  units than the input (:mod:`armaxmodal.prepare.units`).
* ``held_samples`` -- a channel sampled at a lower rate and held to the record's
  (:mod:`armaxmodal.prepare.held`): its repeats keep to a cycle.

The sweep adds ``periodic_disturbance`` (:mod:`armaxmodal.prepare.disturbance`); preparation
(:mod:`armaxmodal.prepare.preparation`) adds ``offset_removed``, ``offset_step``, ``drift``,
``trend_removed`` and ``resampled``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from armaxmodal.notes import QualityWarning, not_run
from armaxmodal.prepare.frf import coherence, welch_segments, welch_spectra
from armaxmodal.recording import Recording
from armaxmodal.stats import QUASI_STATIC_COHERENCE, welch_nperseg

__all__ = ["estimate_delays", "DelayEstimate"]

#: An output less coherent with the input than this (averaged over the input's spectrum) is
#: not its response: response sensors read 0.63-1.00 on the measured records (the F-16, the
#: shake-table IMUs' Northridge and sine rides) and 0.68-1.00 on the fixtures; independent
#: noise about 0.07 (the estimate's bias with 15 segments).
INCOHERENT = 0.3

#: |correlation| above 1 - this is a copy: two physical sensors never agree this well
#: (16-bit quantisation of a proportional copy leaves ~1e-9).
DUPLICATE_TOLERANCE = 1e-6
#: quasi-static band: |T| within these bounds of 1 and coherence at least QUASI_STATIC_COHERENCE
QUASI_STATIC_MAGNITUDE = (0.8, 1.25)
#: Shortest run of equal samples tested (two in a row happen on any quantised channel).
STUCK_MIN_RUN = 3
#: family-wise level of the stuck-samples warning over the channels
STUCK_ALPHA = 0.01
#: a run at the record's first or last sample shorter than this is padding (a channel
#: shifted into alignment repeats its first value a few times), not a dropout: not reported
STUCK_EDGE_MIN = 10
#: a delay is reported when it exceeds this fraction of a sample and is significant at
#: DELAY_ALPHA after Bonferroni correction over the channels; a held (zero-order-hold)
#: input alone shows half a sample on every output, which is the hold, not a defect
MIN_DELAY_SAMPLES = 0.75
DELAY_ALPHA = 0.01
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




@dataclass(frozen=True)
class DelayEstimate:
    """Time offset of one output against the input from the low-frequency transmissibility.

    ``delay_s`` is positive when the output lags; ``sign`` is the low-frequency
    transmissibility's sign (-1: inverted); ``n_lines`` quasi-static lines were used;
    ``delay_sd_s`` is estimated with ``dof`` degrees of freedom (a Student-t quantile, not a
    normal one, makes its interval: there are only a few)."""

    channel: str
    delay_s: float
    delay_sd_s: float
    sign: int
    n_lines: int
    max_freq_hz: float
    dof: int = 1
    #: The delay with each block of Welch segments left out (s; NaN where too few lines
    #: remained): the same blocks for every output, so a delay common to several outputs gets
    #: a jackknife of its own that sees their shared input noise.
    left_out: tuple[float, ...] = field(default=(), compare=False, repr=False)

    def quantile(self, probability: float) -> float:
        """The Student-t quantile with this estimate's degrees of freedom."""
        from scipy.special import stdtrit  # scipy.stats' quantile without its 0.5 s import

        return float(stdtrit(max(self.dof, 1), probability))


def input_coherence(u: np.ndarray, y: np.ndarray, fs: float) -> np.ndarray:
    """Each output's magnitude-squared coherence with the input (Welch, 10 s segments at most
    an eighth of the record), averaged with the input's power as weight: the share of the
    output, at the frequencies the input drives, that a linear response to it explains, (K,)."""
    y = np.asarray(y, float).reshape(len(u), -1)
    nperseg = welch_nperseg(len(u), fs)
    _, puu, puy, pyy = welch_spectra(u, y, fs, nperseg)
    coh = coherence(puu, puy, pyy)
    return puu @ coh / max(float(puu.sum()), 1e-300)


def incoherent_outputs(recording: Recording) -> list[QualityWarning]:
    """Outputs whose coherence with the input (:func:`input_coherence`) is below ``INCOHERENT``."""
    if recording.n_samples < 128:
        return [not_run("incoherent_output", recording.sensors, f"{recording.n_samples} samples, fewer than 128")]
    levels = input_coherence(recording.base, recording.response, recording.fs)
    low = [(name, float(c)) for name, c in zip(recording.sensors, levels, strict=True) if c < INCOHERENT]
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


def _quasi_static_nperseg(recording: Recording) -> int:
    """Welch segment of the quasi-static checks: 20 s at most, an eighth of the record."""
    return welch_nperseg(recording.n_samples, recording.fs, seconds=20.0)


def transmissibility_spectra(recording: Recording):
    """H1 transmissibility of every output and its coherence for the quasi-static checks
    (Welch, 20 s segments at most an eighth of the record): ``(f, h, coh, excited,
    n_segments)``, ``h`` and ``coh`` (n_freq, K), ``excited`` the lines with input power within
    30 dB of its peak; None for a record too short."""
    n = recording.n_samples
    nperseg = _quasi_static_nperseg(recording)
    if nperseg < 16:
        return None
    f, puu, puy, pyy = welch_spectra(recording.base, recording.response, recording.fs, nperseg)
    n_segments = max(1, (n - nperseg) // (nperseg // 2) + 1)
    return f, puy / puu[:, None], coherence(puu, puy, pyy), puu >= puu.max() * 1e-3, n_segments


def estimate_delays(recording: Recording) -> list[DelayEstimate]:
    """Per output: time offset and sign from the quasi-static transmissibility (empty for an
    output without a quasi-static band, e.g. a force input).

    The standard deviation is the larger of the fit's and a delete-a-block jackknife's over
    the Welch segments (blocks of two: a segment overlaps only its neighbours). The fit's
    alone treats the lines as independent; Hann-windowed lines are not, and over 40 clean
    two-sensor rides the delays scattered 1.3-1.6x wider than it said (mean squared
    standardised scatter 1.68 and 2.54; now 1.06 and 1.07): its 95 % interval was too narrow."""
    nperseg = _quasi_static_nperseg(recording)
    if nperseg < 16:
        return []
    f, uf, yf, _ = welch_segments(recording.base, recording.response, recording.fs, nperseg)
    puu, puy, pyy = np.abs(uf) ** 2, np.conj(uf)[:, :, None] * yf, np.abs(yf) ** 2
    n_seg = uf.shape[0]
    blocks = [np.arange(n_seg)] + [np.setdiff1d(np.arange(n_seg), [i, i + 1]) for i in range(0, n_seg, 2)]
    out = []
    for k, name in enumerate(recording.sensors):
        fits = [_fit_segments(f, puu[keep], puy[keep, :, k], pyy[keep, :, k]) for keep in blocks]
        if fits[0] is None:
            continue
        delay, sd, sign, n_lines, f_max = fits[0]
        dof = n_lines - 2
        by_block = tuple(np.nan if fit is None else fit[0] for fit in fits[1:])
        left_out = np.array([d for d in by_block if np.isfinite(d)])
        if left_out.size >= 3:
            jackknife = jackknife_sd(left_out)
            if jackknife > sd:
                sd, dof = float(jackknife), left_out.size - 1
        out.append(DelayEstimate(name, delay, sd, sign, n_lines, f_max, dof, by_block))
    return out


def jackknife_sd(left_out: np.ndarray) -> float:
    """Delete-a-block jackknife standard deviation from the estimates with each block left
    out, (B,): ``sqrt((B - 1) / B * sum (x_b - mean)^2)``."""
    b = left_out.size
    return float(np.sqrt((b - 1) / b * np.sum((left_out - left_out.mean()) ** 2)))


def _fit_segments(f, puu, puy, pyy):
    """:func:`_quasi_static_fit` on the mean of the given segments' spectra."""
    mean_uu, mean_uy, mean_yy = puu.mean(axis=0), puy.mean(axis=0), pyy.mean(axis=0)
    coh = np.abs(mean_uy) ** 2 / np.maximum(mean_uu * mean_yy, 1e-300)
    excited = mean_uu >= mean_uu.max() * 1e-3
    n_segments = max(1, puu.shape[0])
    return _quasi_static_fit(f, mean_uy / np.maximum(mean_uu, 1e-300), coh, excited, n_segments)


def _quasi_static_fit(f, h, coh, excited, n_segments):
    """``(delay_s, sd_s, sign, n_lines, f_max)`` from the lowest contiguous run of excited,
    coherent lines with |T| near 1, or None when there are fewer than 4 such lines."""
    ok = excited & (coh >= QUASI_STATIC_COHERENCE) & (f > 0)
    ok &= (np.abs(h) >= QUASI_STATIC_MAGNITUDE[0]) & (np.abs(h) <= QUASI_STATIC_MAGNITUDE[1])
    if not ok.any():
        return None
    start = int(np.argmax(ok))
    # quasi-static means below the first resonance: a run found only above the coherent rise
    # of |T| (low lines drowned in noise) is past a mode, where the phase is not a delay;
    # incoherent lines below the excited band do not count as a rise
    rise = np.flatnonzero(excited & (coh >= QUASI_STATIC_COHERENCE) & (f > 0) & (np.abs(h) > QUASI_STATIC_MAGNITUDE[1]))
    if rise.size and rise[0] < start:
        return None
    stop = start
    while stop < ok.size and ok[stop]:
        stop += 1
    lines = slice(start, stop)
    if stop - start < 4:
        return None
    # the sign from the lowest lines, where a delay has rotated the phase least: over the whole
    # run a lead of 14 samples at 60 Hz turns it past 90 degrees, and a median of the real part
    # took that for an inverted sensor (and the delay for +18 samples)
    sign = 1 if np.mean(h[start : start + 2].real) > 0 else -1
    phase = np.unwrap(np.angle(sign * h[lines]))
    w = 2 * np.pi * f[lines]
    g2 = np.clip(coh[lines], 1e-6, 1 - 1e-12)
    sd = np.sqrt((1 - g2) / (2 * n_segments * g2))  # H1 phase standard deviation, rad
    design = np.column_stack([-w, w**3]) / sd[:, None]
    coef, *_ = np.linalg.lstsq(design, phase / sd, rcond=None)
    resid = phase / sd - design @ coef
    dof = max(1, resid.size - 2)
    # the fitted model is approximate (higher terms): widen by the residual scatter
    scale = max(1.0, float(resid @ resid) / dof)
    cov = np.linalg.inv(design.T @ design) * scale
    return float(coef[0]), float(np.sqrt(cov[0, 0])), sign, stop - start, float(f[stop - 1])


def delay_and_inversion(recording: Recording) -> list[QualityWarning]:
    """``inverted_sensor`` and ``sensor_delay`` warnings from :func:`estimate_delays`, and a
    ``check_not_run`` note for the outputs it could not test."""
    estimates = estimate_delays(recording)
    tested = {e.channel for e in estimates}
    untested = tuple(s for s in recording.sensors if s not in tested)
    found = []
    if untested:
        found.append(
            not_run(
                "sensor_delay and inverted_sensor",
                untested,
                "no quasi-static lines where the transmissibility to the input is near +-1 (a force input, an "
                "output that does not move with its base below the first mode, or a record too short for lines "
                "below it)",
            )
        )
    inverted = [e.channel for e in estimates if e.sign < 0]
    if len(inverted) > 1 and len(inverted) == len(recording.sensors):
        # every output reads -1: one sign flip on the input explains it, not one per sensor
        found.append(
            QualityWarning(
                "inverted_sensor",
                (recording.input_name,),
                f"every output's low-frequency transmissibility is near -1 where a base-excited structure moves "
                f"with its base (+1): the input '{recording.input_name}' is mounted or exported upside down "
                "(or every output is). Shapes keep the measured sign.",
                -1.0,
            )
        )
    elif inverted:
        found.append(
            QualityWarning(
                "inverted_sensor",
                tuple(inverted),
                f"{', '.join(inverted)}: the low-frequency transmissibility is near -1 where a base-excited "
                "structure moves with its base (+1): the sensor is mounted or exported upside down. "
                "Shapes keep the measured sign.",
                -1.0,
            )
        )
    level = 1 - DELAY_ALPHA / (2 * max(1, len(recording.sensors)))
    dt = 1.0 / recording.fs
    late = [e for e in estimates if abs(e.delay_s) > max(e.quantile(level) * e.delay_sd_s, MIN_DELAY_SAMPLES * dt)]
    if late and len(late) == len(recording.sensors) and len(late) > 1 and all(e.delay_s < 0 for e in late):
        lead = float(np.median([-e.delay_s for e in late]))
        found.append(
            QualityWarning(
                "sensor_delay",
                (recording.input_name,),
                f"every output leads input '{recording.input_name}' by about {1e3 * lead:.1f} ms "
                f"({lead * recording.fs:.2f} samples): the input is late.",
                1e3 * lead,
            )
        )
        return found
    for e in late:
        half = e.quantile(0.975) * e.delay_sd_s
        lo, hi = e.delay_s - half, e.delay_s + half
        verb = "lags" if e.delay_s > 0 else "leads"
        found.append(
            QualityWarning(
                "sensor_delay",
                (e.channel,),
                f"'{e.channel}' {verb} input '{recording.input_name}' by {1e3 * abs(e.delay_s):.1f} ms "
                f"(95 % interval {1e3 * lo:.1f} to {1e3 * hi:.1f} ms, {e.delay_s * recording.fs:.2f} samples; "
                f"phase slope over {e.n_lines} quasi-static lines up to {e.max_freq_hz:.2f} Hz).",
                1e3 * e.delay_s,
            )
        )
    return found


def narrowband_input(recording: Recording) -> list[QualityWarning]:
    """The width of the lines within 10 dB of the input's PSD peak against the peak frequency."""
    n = recording.n_samples
    nperseg = welch_nperseg(n, recording.fs, seconds=20.0, max_fraction=4)
    if nperseg < 16:
        return [not_run("narrowband_input", (recording.input_name,), f"{n} samples, too few for the input's spectrum")]
    f, puu, _, _ = welch_spectra(recording.base, recording.base[:, None], recording.fs, nperseg)
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
            r for r in stuck_runs(data[:, k])
            if r[2] < STUCK_ALPHA / len(names) and (0 < r[0] and r[1] < len(data) or r[1] - r[0] >= STUCK_EDGE_MIN)
        ]  # fmt: skip
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
