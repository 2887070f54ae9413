"""The modal model fitted to the record's DFT lines: one fitter for the refit of the selected
modes and for the maximum-likelihood count (beyond the thesis).

Every sensor's DFT over the excited band is fitted as ``Y = G(Omega) U + T(z) + E``: ``G`` the modal sum with
continuous poles, residues and a direct term, ``T`` the transient (leakage) term with the same poles, exact for
a finite record (Pintelon & Schoukens, *System Identification: a Frequency Domain Approach*, 2nd ed., Ch. 6-7).
The method page's "modal model by maximum likelihood" gives the likelihood, why this form and not a fit to the
H1, and the intervals. The fitter estimates; the selection decides (:mod:`armaxmodal.modes`: which inter-sample
form, how many modes), and hands its damping bounds and tolerance in (``modes.settings.DftSettings``).

**Inter-sample behaviour.** A discrete ARMAX model is the exact model class only when the input is held between
samples (zero-order hold). Measured signals pass anti-aliasing filters and are band-limited: their discrete
transfer function equals the continuous one below Nyquist, which no low-order rational function of ``z``
matches, so the PEM poles carry a model-class bias that depends on where the input has power (measured: a 0.5-20
Hz sweep puts the 16.2 Hz mode 2.9 % low and mode 3's damping 12 % high). ``G`` is written in ``s = i w`` for a
band-limited input or in ``z`` for a held one; :func:`armaxmodal.modes.state.refine_modes` fits both and
the data choose.

The residues, direct and transient terms enter linearly and are projected out (the private
``armaxmodal._separable``): only the frequencies and damping ratios are iterated, all free.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Protocol

import numpy as np
import scipy.optimize

from armaxmodal._separable import GramCompressed, SeparableModel, poles, start_vector, x_bounds
from armaxmodal._threads import single_blas_thread
from armaxmodal.exceptions import OrderError
from armaxmodal.recording import Recording
from armaxmodal.stats import sandwich_sd

__all__ = ["DftLines", "FitLimits", "ModalModel", "fit_modal_model"]

HOLDS = ("bandlimited", "zoh")


class FitLimits(Protocol):
    """What a fit needs of its settings (``armaxmodal.modes.settings.DftSettings`` is one): every
    threshold stays in the selection's settings, none is a default here."""

    min_damping: float  #: the lowest damping ratio a free pole may take
    max_damping: float  #: the highest
    fit_tol: float  #: relative change of the cost and of the parameters at which a fit stops


@dataclass(frozen=True)
class DftLines:
    """The DFT lines of a recording over a band, each sensor scaled by a fixed weight.

    Attributes
    ----------
    s, z_inv : (n_lines,) complex ndarray
        ``i omega`` and ``exp(-i omega dt)`` of the lines.
    u : (n_lines,) complex ndarray
        The base input's DFT.
    y : (n_lines, n_sensors) complex ndarray
        The sensors' DFTs, each multiplied by its weight.
    weights : (n_sensors,) ndarray
        One over each sensor's noise level as first estimated: every candidate model is fitted
        with the same weights, so their likelihoods compare.
    dt : float
        Sampling interval, s.
    band_hz : (float, float)
        The band of the lines, Hz.

    See Also
    --------
    armaxmodal.estimate.dft_model.fit_modal_model : Fits a modal model to them.

    Examples
    --------
    >>> import armaxmodal as am
    >>> from armaxmodal.estimate.dft_model import DftLines
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 60.0, seed=1), 60.0, seed=2)
    >>> data = DftLines.from_recording(ride, (0.5, 28.0))  # 60 s: a line every 1/60 Hz
    >>> data.y.shape, data.n_real, data.band_hz
    ((1651, 4), 3302, (0.5, 28.0))
    """

    s: np.ndarray
    z_inv: np.ndarray
    u: np.ndarray
    y: np.ndarray
    weights: np.ndarray
    dt: float
    band_hz: tuple[float, float]

    @property
    def n_real(self) -> int:
        """Real numbers per sensor (the real and imaginary part of every line)."""
        return 2 * self.s.size

    @classmethod
    def from_recording(cls, recording: Recording, band_hz: tuple[float, float]) -> DftLines:
        """The lines of ``recording`` in ``band_hz`` (Hz), with unit weights (see
        :meth:`weighted`)."""
        dt, (freq, base, response) = 1.0 / recording.fs, recording.dft()  # the record's DFT, computed once
        lines = (freq >= band_hz[0]) & (freq <= band_hz[1]) & (freq > 0)
        if lines.sum() < 8:
            raise OrderError(
                f"{lines.sum()} DFT lines in {band_hz[0]:g}-{band_hz[1]:g} Hz: too few for a modal model; "
                "record longer or widen the band."
            )
        w = 2 * np.pi * freq[lines]
        u, y = base[lines], response[lines]
        band = (float(freq[lines][0]), float(freq[lines][-1]))
        return cls(1j * w, np.exp(-1j * w * dt), u, y, np.ones(y.shape[1]), dt, band)

    def noise_weighted(self, model: ModalModel) -> DftLines:
        """The same lines with each sensor weighted by one over its noise level as ``model``
        leaves it (its residual's RMS per real number).

        Parameters
        ----------
        model : ModalModel
            A model fitted to these lines.

        Returns
        -------
        DftLines
            The same lines, re-weighted.
        """
        level = np.sqrt(model.rss / model.n_real)
        return self.weighted(1.0 / np.where(level > 0, level, 1.0))

    def response_power(self, freq_hz: float, reach: float) -> float:
        """The sensors' power near a frequency: what these lines hold to place a pole there.

        Parameters
        ----------
        freq_hz : float
            The frequency, Hz.
        reach : float
            The lines within this relative frequency of it are summed.

        Returns
        -------
        float
            The sum of ``|Y|^2`` over those lines and every sensor, in the data's units (unweighted).
        """
        near = np.abs(np.abs(self.s) / (2 * np.pi * freq_hz) - 1) <= reach
        return float(np.sum(np.abs(self.y[near] / self.weights) ** 2))

    def weighted_at_start(self, freq_hz, damping, settings: FitLimits) -> DftLines:
        """The same lines with each sensor weighted by one over its noise level at a start: the
        RMS of its residual under the held model with these poles, the residues projected out.

        Parameters
        ----------
        freq_hz, damping : (n_modes,) array_like
            The start's frequencies (Hz) and damping ratios, clipped to the fit's bounds.
        settings : FitLimits
            The damping bounds.

        Returns
        -------
        DftLines
            The same lines, re-weighted.
        """
        start = start_vector(freq_hz, damping)
        lo, hi = x_bounds(np.abs(self.s[0]), self.dt, start.size // 2, settings.min_damping, settings.max_damping)
        held = SeparableModel(self.s, self.z_inv, self.u, self.y / self.weights, self.dt, "zoh")
        return self.weighted(1.0 / held.residual_rms(np.clip(start, lo, hi)))

    def weighted(self, weights: np.ndarray) -> DftLines:
        """The same lines with each sensor multiplied by ``weights`` (replacing the old ones).

        Parameters
        ----------
        weights : (n_sensors,) ndarray
            One positive weight per sensor.

        Returns
        -------
        DftLines
            The same lines, re-weighted.
        """
        y = self.y / self.weights * weights
        return DftLines(self.s, self.z_inv, self.u, y, np.asarray(weights, float), self.dt, self.band_hz)


@dataclass(frozen=True)
class ModalModel:
    """A modal model fitted to a recording's DFT lines by maximum likelihood.

    Attributes
    ----------
    freq_hz, damping, freq_sd, damping_sd : (n_modes,) ndarray
        Undamped natural frequencies (Hz), damping ratios and their standard deviations, by
        frequency.
    shapes : (n_sensors, n_modes) complex ndarray
        EPFRF modal constants (Eq. 3.24), ``-r / lambda^2`` from the continuous residues.
    rss : (n_sensors,) ndarray
        Each sensor's residual sum of squares, in the data's units (not weighted): the
        likelihood of fits under different weights compare.
    n_real : int
        Real numbers per sensor the model was fitted to.
    hold : str
        Inter-sample assumption ("bandlimited" or "zoh").
    residual : (n_lines, n_sensors) complex ndarray
        The weighted residual of every line: where a missing mode or a model error sits.
    converged : bool
        The fit met its tolerance (False: it stopped at its cap of evaluations, as a screening
        fit is meant to).
    band_hz : (float, float)
        The band of the fitted lines, Hz.
    nyquist_hz : float
        The highest frequency a pole can take (the fit's bound), Hz.
    hold_cost : dict
        From :func:`armaxmodal.modes.state.refine_modes`: each tried assumption's weighted residual sum of squares from
        the same start, the basis of its choice (empty for a plain fit).
    at_bound : (n_modes,) bool ndarray or None
        The pole's frequency or damping is held at a bound of the fit (the solver's active set):
        its Wald interval means nothing there. None: not known.
    damping_floor : float
        The lowest damping ratio the fit allowed (its settings' ``min_damping``).

    See Also
    --------
    armaxmodal.estimate.dft_model.fit_modal_model : What makes one.

    Examples
    --------
    >>> import armaxmodal as am
    >>> body, exact = am.supine_human(), am.supine_human().modes()  # exact: 5.83, 8.31, 13.50, 16.25 Hz
    >>> ride = am.simulate_recording(body, am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03, seed=2)
    >>> from armaxmodal.estimate.dft_model import DftLines, fit_modal_model
    >>> from armaxmodal.modes.settings import DEFAULTS
    >>> data = DftLines.from_recording(ride, (0.5, 28.0))
    >>> model = fit_modal_model(data, exact.freq_hz, exact.damping, hold="zoh", settings=DEFAULTS.dft)
    >>> model.n_modes, model.n_params, [round(float(x), 2) for x in model.damping]  # exact: 0.26, 0.35, 0.30, 0.27
    (4, 72, [0.26, 0.35, 0.3, 0.27])
    """

    freq_hz: np.ndarray
    damping: np.ndarray
    freq_sd: np.ndarray
    damping_sd: np.ndarray
    shapes: np.ndarray
    rss: np.ndarray
    n_real: int
    hold: str
    residual: np.ndarray
    converged: bool = True
    band_hz: tuple[float, float] = (0.0, np.inf)
    hold_cost: dict = field(default_factory=dict)
    nyquist_hz: float = np.inf
    at_bound: np.ndarray | None = None
    damping_floor: float = 0.0

    def by_frequency(self) -> ModalModel:
        """The same model, its modes sorted by frequency.

        Returns
        -------
        ModalModel
            A copy whose per-mode arrays and shape columns are in ascending frequency.
        """
        order = np.argsort(self.freq_hz)
        return replace(
            self,
            freq_hz=self.freq_hz[order],
            damping=self.damping[order],
            freq_sd=self.freq_sd[order],
            damping_sd=self.damping_sd[order],
            shapes=self.shapes[:, order],
            at_bound=None if self.at_bound is None else self.at_bound[order],
        )

    @property
    def n_modes(self) -> int:
        return int(self.freq_hz.size)

    @property
    def n_params(self) -> int:
        """Free real parameters that depend on the number of modes: per mode, its pole (2),
        and per sensor a complex residue and a complex transient coefficient (4)."""
        return self.n_modes * (2 + 4 * self.rss.size)

    @property
    def neg2_loglik(self) -> float:
        """``-2 ln L`` concentrated over each sensor's noise variance (constants dropped)."""
        return float(self.n_real * np.sum(np.log(self.rss / self.n_real)))

    def bic(self, n_effective: float | None = None) -> float:
        """Schwarz's criterion ``-2 ln L + p ln N`` (Schwarz 1978), with ``N`` the real numbers
        fitted. ``n_effective`` (the real numbers of independent information, at most ``N``)
        scales the likelihood and sets the penalty where the residual is correlated across
        lines (:func:`armaxmodal.stats.effective_fraction`).

        Parameters
        ----------
        n_effective : float, optional
            Real numbers of independent information (default: all fitted).

        Returns
        -------
        float
            The criterion; smaller is better.
        """
        n_eff = self._effective(n_effective)
        return self.neg2_loglik_on(n_eff) + self.n_params * np.log(n_eff)

    def neg2_loglik_on(self, n_effective: float | None = None) -> float:
        """``-2 ln L`` scaled to ``n_effective`` independent real numbers, as :meth:`bic` uses it:
        the difference of two models' values is their likelihood ratio on the effective lines.

        Parameters
        ----------
        n_effective : float, optional
            Real numbers of independent information (default: all fitted).

        Returns
        -------
        float
        """
        return self.neg2_loglik * self._effective(n_effective) / (self.n_real * self.rss.size)

    def _effective(self, n_effective: float | None) -> float:
        n_total = self.n_real * self.rss.size
        return n_total if n_effective is None else min(float(n_effective), n_total)


@single_blas_thread
def fit_modal_model(
    data: DftLines,
    freq_hz,
    damping,
    hold: str = "bandlimited",
    max_nfev: int = 40,
    *,
    settings: FitLimits,
    intervals: bool = True,
    by_frequency: bool = True,
) -> ModalModel:
    """Fit the modal model with every pole free, from a start.

    Parameters
    ----------
    data : DftLines
        The recording's lines and the sensors' weights.
    freq_hz, damping : (n_modes,) array_like
        Starting frequencies (Hz) and damping ratios.
    hold : {"bandlimited", "zoh"}
        Inter-sample assumption (see the module notes).
    max_nfev : int
        Cap on residual evaluations.
    settings : FitLimits
        The damping bounds and the stopping tolerance (the selection's ``DEFAULTS.dft``).
    intervals : bool
        Compute the standard deviations (False: NaN, for a fit compared by its criterion alone;
        the sandwich's rows are a sixth of a screening fit's time).
    by_frequency : bool
        Sort the modes by frequency (False: in the start's order).

    Returns
    -------
    ModalModel
        The fit.

    See Also
    --------
    armaxmodal.estimate.dft_model.ModalModel : What it returns.
    armaxmodal.estimate.dft_model.DftLines : The lines it fits.

    Examples
    --------
    >>> import armaxmodal as am
    >>> from armaxmodal.estimate.dft_model import DftLines, fit_modal_model
    >>> from armaxmodal.modes.settings import DEFAULTS
    >>> body = am.supine_human()
    >>> ride = am.simulate_recording(body, am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03, seed=2)
    >>> exact, data = body.modes(), DftLines.from_recording(ride, (0.5, 28.0))
    >>> model = fit_modal_model(data, exact.freq_hz * 1.02, exact.damping, hold="zoh", settings=DEFAULTS.dft)
    >>> [round(float(f), 1) for f in model.freq_hz]  # exact: 5.83, 8.31, 13.50, 16.25 Hz
    [5.8, 8.3, 13.6, 16.2]
    """
    if hold not in HOLDS:
        raise ValueError(f"hold: expected 'bandlimited' or 'zoh', got {hold!r}.")
    model = _fit(data, start_vector(freq_hz, damping), hold, max_nfev, settings, intervals)
    return model.by_frequency() if by_frequency else model


def _fit(
    data: DftLines, start: np.ndarray, hold: str, max_nfev: int, settings: FitLimits, intervals: bool = True
) -> ModalModel:
    """The fit from ``start`` (``(ln omega_n, xi)`` per mode), its modes in the start's order,
    under the caller's BLAS threads."""
    n = start.size // 2
    if 2 * data.s.size < 3 * (4 * n + 2):  # plant and transient pairs, direct and constant terms
        lo_hz, hi_hz = data.band_hz
        raise OrderError(
            f"{data.s.size} DFT lines in {lo_hz:g}-{hi_hz:g} Hz cannot fit {n} modes; record longer or widen the band."
        )
    lo, hi = x_bounds(np.abs(data.s[0]), data.dt, n, settings.min_damping, settings.max_damping)
    start = np.clip(start, lo + 1e-9, hi - 1e-9)
    model = SeparableModel(data.s, data.z_inv, data.u, data.y, data.dt, hold)
    compressed = GramCompressed(model)
    res = scipy.optimize.least_squares(
        compressed.residual,
        start,
        jac=compressed.jacobian,
        bounds=(lo, hi),
        x_scale="jac",
        max_nfev=max_nfev,
        ftol=settings.fit_tol,
        xtol=settings.fit_tol,
    )
    model.residual(res.x)
    coef, resid = model.coef, model.resid
    rss = np.sum(resid**2, axis=0) / data.weights**2  # in the data's units: fits under other weights compare
    sd = sandwich_sd(model.sensor_rows(res.x), coef.size + res.x.size) if intervals else np.full(res.x.size, np.nan)
    lam = poles(res.x)
    r = (coef[0 : 2 * n : 2] + 1j * coef[1 : 2 * n : 2]).T / data.weights[:, None]
    if hold == "zoh":  # R / (1 - mu z^-1) = R + R mu z^-1 / (1 - mu z^-1); zoh of r / (s - lambda)
        mu = np.exp(lam * data.dt)  # is r (mu - 1) / lambda z^-1 / (1 - mu z^-1), so r = R mu lambda / (mu - 1)
        r = r * mu * lam / (mu - 1.0)
    model.release()
    f = np.abs(lam) / (2 * np.pi)
    return ModalModel(
        freq_hz=f,
        damping=-lam.real / np.abs(lam),
        freq_sd=f * sd[0::2],
        damping_sd=sd[1::2],
        shapes=-r / lam**2,
        rss=rss,
        n_real=data.n_real,
        hold=hold,
        residual=resid[: data.s.size] + 1j * resid[data.s.size :],
        converged=bool(res.status > 0),  # 0: stopped at max_nfev
        band_hz=data.band_hz,
        nyquist_hz=0.5 / data.dt,
        at_bound=(res.active_mask != 0).reshape(n, 2).any(axis=1),
        damping_floor=settings.min_damping,
    )
