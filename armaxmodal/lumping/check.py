"""Can two segments be modelled as one mass? (thesis Chapter 5: legs and feet)

Two segments move as one when, wherever their motion relative to the base is measurable,
the transmissibility between them (Eq. 5.1) is near 1 with little phase, and the two
relative motions are coherent; the wavelet coherence (Eqs. 5.4-5.5) shows whether that holds
all through the ride (a sweep visits each frequency once) and with what lag.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from armaxmodal.exceptions import DataError
from armaxmodal.lumping.wavelet import WaveletCoherence, scalogram, wavelet_coherence
from armaxmodal.recording import Recording
from armaxmodal.spectra import excited_band, welch_spectra
from armaxmodal.stats import H1_COHERENCE, welch_nperseg

__all__ = ["LumpCheck", "lump_check", "relative_transmissibility", "LIMITS"]

#: what "moves as one" means: |T| within [1/gain, gain] and phase within phase_deg, judged
#: where both relative motions are coherent with the base at least ``measurable`` (elsewhere
#: sensor noise dominates them and T says nothing).
LIMITS = {"gain": 1.25, "phase_deg": 15.0, "measurable": H1_COHERENCE, "agree_fraction": 0.9}


def relative_transmissibility(rec: Recording, a: str, b: str, nperseg: int | None = None):
    """Eq. 5.1: ``T = A_br / A_ar``, the motion of ``b`` over that of ``a``, both relative to
    the base (absolute accelerations minus the base's).

    Estimated as the ratio of the two relative motions' H1 against the base, so noise on
    either sensor (uncorrelated with the base) does not bias it -- an H1 with ``a`` as the
    reference would be pulled below 1 by ``a``'s own sensor noise wherever the relative
    motion is small.

    Parameters
    ----------
    rec : Recording
    a, b : str
        The two sensors' names.
    nperseg : int, optional
        Welch segment length (default: the recording's own).

    Returns
    -------
    freq_hz : (n_freq,) ndarray
    t : (n_freq,) complex ndarray
    coherence : (n_freq,) ndarray
        Between the two relative motions.
    measurable : (n_freq,) ndarray
        The smaller coherence of either relative motion with the base.

    See Also
    --------
    armaxmodal.lumping.lump_check : Judges two segments by it.

    Examples
    --------
    The feet's motion relative to the base over the legs', well below the feet's own mode
    (24.8 Hz) and at it:

    >>> import numpy as np
    >>> import armaxmodal as am
    >>> from armaxmodal.lumping import relative_transmissibility
    >>> ride = am.simulate_recording(am.supine_with_feet(), am.random_vibration(60.0, 120.0, seed=1), 60.0,
    ...                              noise=0.03, seed=2)
    >>> f, t, coherence, measurable = relative_transmissibility(ride, "legs", "feet")
    >>> [round(float(np.median(np.abs(t[(f > lo) & (f < hi)]))), 1) for lo, hi in ((2, 5), (23, 26))]
    [0.6, 2.0]
    """
    for s in (a, b):
        if s not in rec.sensors:
            raise DataError(f"no sensor {s!r} in the recording; its sensors are {list(rec.sensors)}.")
    if a == b:
        raise DataError(f"a segment cannot be lumped with itself ({a!r}); name two different sensors.")
    # a ratio of two noisy relative motions wants averages more than resolution: 30 segments or more
    n = nperseg or welch_nperseg(rec.n_samples, rec.fs, max_fraction=16)
    rel = np.column_stack([rec.channel(a) - rec.base, rec.channel(b) - rec.base])
    f, puu, pur, prr = welch_spectra(rec.base, rel, rec.fs, n)
    t = pur[:, 1] / np.where(np.abs(pur[:, 0]) > 0, pur[:, 0], np.nan)
    with_base = np.abs(pur) ** 2 / (puu[:, None] * prr)
    _, paa, pab, pbb = welch_spectra(rel[:, 0], rel[:, 1:], rec.fs, n)
    coh = np.abs(pab[:, 0]) ** 2 / (paa * pbb[:, 0])
    return f, t, coh, with_base.min(axis=1)


@dataclass(frozen=True)
class LumpCheck:
    """The answer and its evidence (see :func:`~armaxmodal.lumping.lump_check`).

    See Also
    --------
    armaxmodal.lumping.lump_check : What makes one.

    Examples
    --------
    >>> import armaxmodal as am
    >>> ride = am.simulate_recording(am.supine_with_feet(), am.random_vibration(60.0, 120.0, seed=1), 60.0,
    ...                              noise=0.03, seed=2)
    >>> check = am.lump_check(ride, "legs", "feet", wavelet=False)
    >>> check.verdict, round(check.band[1], 1), int(check.measurable.sum()), int(check.agrees.sum())
    ('separate', 28.1, 204, 1)
    """

    a: str
    b: str
    band: tuple[float, float]
    freq_hz: np.ndarray
    transmissibility: np.ndarray
    coherence: np.ndarray
    measurable: np.ndarray
    agrees: np.ndarray
    verdict: str
    message: str
    wavelet: WaveletCoherence | None = None
    wavelet_summary: dict | None = None
    scalograms: dict | None = None

    def to_dict(self) -> dict:
        """JSON-ready: the verdict, its sentence, and the numbers behind them.

        Returns
        -------
        dict
            Strict-JSON-ready (no NaN).
        """
        use = self._used()
        gain = np.abs(self.transmissibility[use])
        phase = np.degrees(np.angle(self.transmissibility[use]))
        return {
            "a": self.a,
            "b": self.b,
            "band_hz": list(self.band),
            "verdict": self.verdict,
            "message": self.message,
            "limits": LIMITS,
            "frequencies_used": int(use.sum()),
            "agree_fraction": float(self.agrees[use].mean()) if use.any() else None,
            "first_disagreement_hz": self.first_disagreement(),
            "gain_range": [float(gain.min()), float(gain.max())] if use.any() else None,
            "max_abs_phase_deg": float(np.abs(phase).max()) if use.any() else None,
            "min_coherence": float(self.coherence[use].min()) if use.any() else None,
            "wavelet": self.wavelet_summary,
        }

    def _used(self) -> np.ndarray:
        f = self.freq_hz
        return (f >= self.band[0]) & (f <= self.band[1]) & (self.measurable >= LIMITS["measurable"])

    def first_disagreement(self) -> float | None:
        """Lowest frequency (Hz) of the first run of two or more disagreeing frequencies.

        Returns
        -------
        float or None
            Hz; None when no two neighbouring frequencies disagree.
        """
        use = np.flatnonzero(self._used())
        bad = use[~self.agrees[use]]
        runs = bad[np.flatnonzero(np.diff(bad) == 1)] if bad.size > 1 else np.array([], int)
        return float(self.freq_hz[runs[0]]) if runs.size else None


def lump_check(
    rec: Recording, a: str, b: str, band: tuple[float, float] | None = None, *, wavelet: bool = True
) -> LumpCheck:
    """Whether segments ``a`` and ``b`` can be modelled as one mass, in plain words.

    Parameters
    ----------
    rec : Recording
        Absolute accelerations of the sensors and of the base.
    a, b : str
        The two segments (e.g. ``"legs"``, ``"feet"``); ``T = b / a``.
    band : (lo, hi) Hz, optional
        Frequencies that matter (default: where the input is excited, within 30 dB of its peak).
    wavelet : bool
        Also the wavelet coherence of the two relative motions, with its 95 % red-noise level.

    Returns
    -------
    LumpCheck
        ``verdict`` is "lump", "separate" or "undetermined" (too few measurable frequencies).

    See Also
    --------
    armaxmodal.lumping.LumpCheck : What it returns.
    armaxmodal.lumping.wavelet_coherence : Its time-frequency evidence.

    Examples
    --------
    Do the legs and feet of the five-segment body move as one mass?

    >>> import armaxmodal as am
    >>> ride = am.simulate_recording(am.supine_with_feet(), am.random_vibration(60.0, 120.0, seed=1), 60.0,
    ...                              noise=0.03, seed=2)
    >>> am.lump_check(ride, "legs", "feet", wavelet=False).verdict
    'separate'
    """
    f, t, coh, measurable = relative_transmissibility(rec, a, b)
    t = np.where(np.isfinite(t), t, 0.0)
    band = tuple(float(v) for v in (band or excited_band(rec)))
    gain_ok = (np.abs(t) <= LIMITS["gain"]) & (np.abs(t) >= 1 / LIMITS["gain"])
    agrees = gain_ok & (np.abs(np.degrees(np.angle(t))) <= LIMITS["phase_deg"])
    check = LumpCheck(a, b, band, f, t, coh, measurable, agrees, "undetermined", "")
    use = check._used()
    wave = summary = scalograms = None
    if wavelet and use.sum() >= 2:
        wave, summary, scalograms = _wavelet_evidence(rec, a, b, (f[use].min(), f[use].max()))
    verdict, message = _verdict(check, use, summary)
    return LumpCheck(a, b, band, f, t, coh, measurable, agrees, verdict, message, wave, summary, scalograms)


def _verdict(check: LumpCheck, use: np.ndarray, wave: dict | None) -> tuple[str, str]:
    a, b = check.a, check.b
    if use.sum() < 5:
        return "undetermined", (
            f"{a} and {b}: their motion relative to the base is buried in sensor noise at almost every frequency "
            f"of {check.band[0]:.1f}-{check.band[1]:.1f} Hz; the data cannot say whether they move as one."
        )
    d = check.to_dict()
    lo, hi = check.freq_hz[use].min(), check.freq_hz[use].max()
    evidence = (
        f"|T| {d['gain_range'][0]:.2f}-{d['gain_range'][1]:.2f}, phase within {d['max_abs_phase_deg']:.0f} deg, "
        f"over {lo:.1f}-{hi:.1f} Hz"
    )
    if wave is not None:
        evidence += (
            f"; wavelet coherence median {wave['median_r2']:.2f} along the excitation, "
            f"lag {wave['mean_phase_deg']:.0f} deg"
        )
    if d["agree_fraction"] >= LIMITS["agree_fraction"] and d["first_disagreement_hz"] is None:
        return "lump", f"{a} and {b} move as one ({evidence}): they can be modelled as one segment."
    start = d["first_disagreement_hz"] or lo
    return "separate", (
        f"{b} moves apart from {a} from {start:.1f} Hz ({evidence}): model {b} as a separate mass if the "
        f"band of interest reaches {start:.1f} Hz; below it they can be lumped."
    )


def _wavelet_evidence(rec: Recording, a: str, b: str, band) -> tuple[WaveletCoherence, dict, dict]:
    """Coherence of the relative motions along the excitation's ridge (where the base's own
    scalogram is within 6 dB of its strongest scale at that instant, inside the cone)."""
    ra, rb = rec.channel(a) - rec.base, rec.channel(b) - rec.base
    wave = wavelet_coherence(ra, rb, rec.fs, band)
    base = scalogram(rec.base, rec.fs, band)
    power = base.power
    ridge = (power >= 0.25 * power.max(axis=0, keepdims=True)) & base.inside_coi()
    r2 = wave.r2[ridge]
    weights = r2 / max(r2.sum(), 1e-12)
    mean_phase = np.angle(np.sum(weights * np.exp(1j * wave.phase_rad[ridge])))
    summary = {
        "median_r2": float(np.median(r2)) if r2.size else None,
        "above_95pct_red_noise": float(np.mean(r2 > wave.significance[np.nonzero(ridge)[0]])) if r2.size else None,
        "mean_phase_deg": float(np.degrees(mean_phase)),
        "omega0": 5.0,
    }
    scalograms = {"base": base, a: scalogram(ra, rec.fs, band), b: scalogram(rb, rec.fs, band)}
    return wave, summary, scalograms
