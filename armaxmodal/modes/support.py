"""The support tests: does the record need a mode, and is a pole a mode of it?

Every rule that keeps, drops or admits a mode on the record's evidence, in one place:

* ``mode_support`` -- the modal-model check's misfit with and without a mode, a neighbour
  refitted in its place (``ModeSupport``: needed when the rise is large and significant),
  which :mod:`armaxmodal.modes.completeness` uses to drop and add modes;
* ``peak_support`` -- a clear, coherent FRF peak a mode explains (a weakly supported
  cluster of the diagram is rescued by one, :mod:`armaxmodal.modes.clusters`);
* ``stable_in_diagram`` -- a pole is stable across the diagram's orders (the maximum-likelihood
  count admits only such new poles, :mod:`armaxmodal.modes.mode_count`).

The count's own tests (damping resolved, the same mode in both halves of the record) act on the
modal model's fits and live with its search (:mod:`armaxmodal.modes.mode_count`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from armaxmodal.modes.frf import coherent_lines, coherent_peaks, explains, resolving_nperseg
from armaxmodal.modes.modal_check import ModalCheck, poles_of, rss_at
from armaxmodal.modes.poles import SHARED
from armaxmodal.modes.settings import DEFAULTS, ClusterSettings, FrfSettings
from armaxmodal.recording import Recording

__all__ = ["ModeSupport", "mode_support", "nearest_neighbour",
           "overlapping_neighbour", "peak_support", "stable_in_diagram"]  # fmt: skip

@dataclass(frozen=True)
class ModeSupport:
    """How much the check needs one mode: each output's relative misfit with and without it
    (a neighbour within its half-power band refitted in its place), and the F-test's p."""

    error_with: np.ndarray
    error_without: np.ndarray
    p_value: float
    refitted_neighbour: int | None
    settings: FrfSettings = DEFAULTS.frf

    @property
    def rise(self) -> float:
        """The largest relative rise of an output's misfit without the mode."""
        ratio = self.error_without / np.maximum(self.error_with, 1e-300)
        finite = ratio[np.isfinite(ratio)]
        return float(finite.max() - 1) if finite.size else float("nan")

    @property
    def needed(self) -> bool:
        """The rise is at least ``settings.model_error_rise`` and significant at ``settings.support_alpha``."""
        return bool(self.rise >= self.settings.model_error_rise and self.p_value <= self.settings.support_alpha)


def overlapping_neighbour(freq_hz, damping, m: int) -> int | None:
    """The nearest mode whose half-power band overlaps mode ``m``'s
    (``|f_i - f_m| < xi_i f_i + xi_m f_m``), or None."""
    f, x = np.asarray(freq_hz, dtype=float), np.asarray(damping, dtype=float)
    gap = np.abs(f - f[m])
    close = [i for i in range(f.size) if i != m and gap[i] < x[i] * f[i] + x[m] * f[m]]
    return min(close, key=lambda i: gap[i]) if close else None


def nearest_neighbour(freq_hz, damping, m: int, bandwidths: float = DEFAULTS.frf.neighbour_bandwidths) -> int | None:
    """The mode nearest mode ``m`` within ``bandwidths`` half-power bandwidths
    (``2 xi f``, the wider of the two), or None: the mode whose pole may take over what
    ``m`` fits. A spurious pole beside a lightly damped mode corrects that mode's slightly
    biased pole at the peak; with the neighbour's pole refitted it is not needed."""
    f, x = np.asarray(freq_hz, dtype=float), np.asarray(damping, dtype=float)
    gap = np.abs(f - f[m])
    reach = bandwidths * np.maximum(2 * x * f, 2 * x[m] * f[m])
    close = [i for i in range(f.size) if i != m and gap[i] <= reach[i]]
    return min(close, key=lambda i: gap[i]) if close else None


def mode_support(
    recording: Recording, freq_hz, damping, m: int, check: ModalCheck, band=None, *, reach: str = "overlapping",
    settings: FrfSettings = DEFAULTS.frf,
) -> ModeSupport:
    """How much the check of ``check`` needs mode ``m`` (see ``ModeSupport``).

    The fit without the mode keeps each output's delay. A neighbour -- ``reach="overlapping"``:
    a mode whose half-power band overlaps this one's (:func:`overlapping_neighbour`);
    ``"nearest"``: the nearest within ``settings.neighbour_bandwidths`` (:func:`nearest_neighbour`),
    the stricter test a mode the diagram supports weakly must pass to enter -- has its
    frequency and damping refitted (Nelder-Mead on the summed relative residual, residues
    projected out) so it may take over: two poles always fit one peak at least as well as
    one, so only a refitted single pole shows whether the record needs both. A neighbour
    that moves more than ``settings.neighbour_max_shift`` to take over is not refitted. The F-test
    compares the summed relative residual sums with ``q = 2 n_outputs`` (the residues)
    ``+ 2`` (the pole, unless the neighbour's refit spends them) over ``sum(lines) -
    parameters`` degrees of freedom (one per complex line: the Hann-windowed,
    half-overlapped lines are correlated in pairs).
    """
    from scipy.optimize import minimize
    from scipy.special import fdtrc  # F survival function without scipy.stats' import

    f, x = np.asarray(freq_hz, dtype=float), np.asarray(damping, dtype=float)
    all_lines = coherent_lines(recording, check.nperseg, band)
    used = [k for k, lines in enumerate(all_lines) if np.isfinite(check.error[k])]
    norms = {k: float(np.sum(np.abs(all_lines[k].h) ** 2)) for k in used}

    def relative_rss(poles) -> np.ndarray:
        return np.array([rss_at(all_lines[k], poles, check.delay_s[k]) / norms[k] for k in used])

    keep = [i for i in range(f.size) if i != m]
    with_m = relative_rss(poles_of(f, x))
    if reach == "nearest":
        j = nearest_neighbour(f, x, m, settings.neighbour_bandwidths)
    else:
        j = overlapping_neighbour(f, x, m)
    fk, xk = f[keep], x[keep]
    if j is not None:
        at = keep.index(j)

        def cost(p):
            fj, xj = fk.copy(), xk.copy()
            fj[at], xj[at] = f[j] * np.exp(p[0]), min(x[j] * np.exp(p[1]), 0.9)
            return float(np.sum(relative_rss(poles_of(fj, xj))))

        best = minimize(cost, np.zeros(2), method="Nelder-Mead", options={"xatol": 1e-4, "fatol": 1e-9, "maxiter": 200})
        if abs(np.exp(best.x[0]) - 1) <= settings.neighbour_max_shift:
            fk, xk = fk.copy(), xk.copy()
            fk[at], xk[at] = f[j] * np.exp(best.x[0]), min(x[j] * np.exp(best.x[1]), 0.9)
        else:  # it took over only by leaving its own place: the two are distinct modes
            j = None
    without = relative_rss(poles_of(fk, xk))
    n_obs = sum(all_lines[k].freq_hz.size for k in used)
    q = 2 * len(used) + (0 if j is not None else 2)
    dof = n_obs - len(used) * (2 * f.size + 5) - 2 * f.size
    s1, s0 = float(with_m.sum()), float(without.sum())
    stat = ((s0 - s1) / q) / (s1 / dof) if dof > 0 and s1 > 0 else float("nan")
    p = float(fdtrc(q, dof, stat)) if np.isfinite(stat) and stat > 0 else 1.0
    return ModeSupport(np.sqrt(with_m), np.sqrt(without), p, j, settings)


def peak_support(recording: Recording, freq_hz: float, damping: float, band=None) -> float | None:
    """Frequency of the clear, coherent FRF peak (:func:`coherent_peaks`) that a mode at
    ``freq_hz`` explains, or None: the data's own evidence for a mode whose poles alone are
    not conclusive (a lightly damped pole whose damping estimate crosses zero)."""
    n = resolving_nperseg(recording, [freq_hz], [max(damping, 1e-6)])
    df = recording.fs / n
    near = [p for p in coherent_peaks(recording, n, band) if explains(p[0], df, [freq_hz], [max(damping, 0.0)])]
    return max(near, key=lambda p: p[2])[0] if near else None


def stable_in_diagram(diagram, band, cluster: ClusterSettings):
    """``supported(f, x)``: poles of at least ``cluster.min_orders`` orders of the diagram
    lie within the clustering's reach of frequency ``f`` (Hz) and damping ``x``. Poles rejected
    for their residue count: stability across orders is the pole's, and a weakly driven mode (a
    light chain's 9.32 Hz, rejected as a negligible residue at every order) is still a mode."""
    poles = diagram.poles[diagram.poles.source == SHARED]
    if band is not None:
        poles = poles[(poles.freq_hz >= band[0]) & (poles.freq_hz <= band[1])]
    kept = poles[poles.damping > 0]
    f, x, na = kept.freq_hz.to_numpy(), kept.damping.to_numpy(), kept.na.to_numpy()

    def supported(freq_hz: float, damping: float) -> bool:
        near = (np.abs(f / freq_hz - 1) <= cluster.freq) & (np.abs(x / damping - 1) <= cluster.damping)
        return len(set(na[near].tolist())) >= cluster.min_orders

    return supported
