"""The sensors' time offsets and signs from the quasi-static transmissibility (checks run
before any fit: ``sensor_delay`` and ``inverted_sensor``).

Below the first mode a base-excited structure
moves with its base: the absolute-acceleration transmissibility is ``1 + O(w^2)`` with a
phase of order ``w^3`` (``T = 1 - w^2 K^-1 M e + ...``). A low-frequency ``T`` near -1 is a
sensor mounted or exported upside down; a phase that grows *linearly* with frequency is a
time offset, ``phase = -w tau``. The slope is fitted with the cubic term over the
quasi-static lines, weighted by the H1 phase variance (Bendat & Piersol 9.2.4).
Recordings whose low-frequency transmissibility is not near +-1 (a force input, no
quasi-static band) are not tested, and the check says nothing.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from armaxmodal.quality_warnings import QualityWarning, not_run
from armaxmodal.recording import Recording
from armaxmodal.spectra import coherence, welch_segments
from armaxmodal.stats import QUASI_STATIC_COHERENCE, welch_nperseg

__all__ = [
    "DELAY_ALPHA",
    "MIN_DELAY_SAMPLES",
    "QUASI_STATIC_MAGNITUDE",
    "DelayEstimate",
    "delay_and_inversion",
    "estimate_delays",
    "jackknife_sd",
    "transmissibility_spectra",
]

#: quasi-static band: |T| within these bounds of 1 and coherence at least QUASI_STATIC_COHERENCE
QUASI_STATIC_MAGNITUDE = (0.8, 1.25)
#: a delay is reported when it exceeds this fraction of a sample and is significant at
#: DELAY_ALPHA after Bonferroni correction over the channels; a held (zero-order-hold)
#: input alone shows half a sample on every output, which is the hold, not a defect
MIN_DELAY_SAMPLES = 0.75
DELAY_ALPHA = 0.01


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
    f, puu, puy, pyy = recording.welch(nperseg)
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
