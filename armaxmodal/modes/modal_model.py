"""The modal model by maximum likelihood, and its likelihood for nested tests (beyond the thesis).

Every sensor's DFT over the excited band is fitted as ``Y = G(Omega) U + T(z) + E``
(:mod:`armaxmodal.modes.refine`): ``G`` the modal sum with continuous poles, residues and a
direct term, ``T`` the transient (leakage) term with the same poles. This is the output-error
form of the modal model written on DFT lines (Pintelon & Schoukens, *System Identification:
a Frequency Domain Approach*, 2nd ed., Sec. 6.3): with the transient term it is exact for a
finite record, so, unlike a fit to a Welch-averaged H1, it has no frequency-resolution limit.
That is why it is chosen over the H1 form of the ML-MM estimator (El-Kafafy, Guillaume &
Peeters, Appl. Sci. 9 (2019) 3120): a lightly damped mode's half-power band (0.04 Hz at
0.3 % and 6 Hz) is narrower than any Welch line a 120 s ride allows, while the DFT's line is
1 / T.

With white output noise of variance ``sigma_k^2`` on sensor ``k``, its DFT lines are
independent complex normal variables of equal variance, so the log-likelihood concentrated
over the ``sigma_k`` is ``-1/2 sum_k n_k ln(RSS_k / n_k)`` (``n_k`` real numbers per sensor):
minimising each sensor's weighted residual is maximum likelihood. The residues, direct and
transient terms enter linearly and are projected out (variable projection, Golub & Pereyra),
so only the frequencies and damping ratios are iterated, all of them free. Standard errors
come from the Jacobian of the projected residual (the information matrix, as a sandwich).

:class:`DftLines` holds the data once; :func:`fit_modal_model` fits one set of starting
modes; :class:`ModalModel` carries the fit and its information criterion.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.optimize

from armaxmodal._threads import single_blas_thread
from armaxmodal.exceptions import OrderError
from armaxmodal.modes.refine import _poles, _sandwich_sd, _SeparableModel
from armaxmodal.modes.settings import DEFAULTS, DftSettings
from armaxmodal.recording import Recording

__all__ = ["DftLines", "ModalModel", "fit_modal_model"]


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
        dt = 1.0 / recording.fs
        freq = np.fft.rfftfreq(recording.n_samples, dt)
        lines = (freq >= band_hz[0]) & (freq <= band_hz[1]) & (freq > 0)
        if lines.sum() < 8:
            raise OrderError(
                f"{lines.sum()} DFT lines in {band_hz[0]:g}-{band_hz[1]:g} Hz: too few for a modal model; "
                "record longer or widen the band."
            )
        w = 2 * np.pi * freq[lines]
        u = np.fft.rfft(recording.base)[lines]
        y = np.fft.rfft(recording.response, axis=0)[lines]
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
        lines (:func:`armaxmodal.modes.mode_count.effective_fraction`).

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


class _GramCompressed:
    """The projected residual and Jacobian reduced to ``n + 1`` rows through the normal
    equations: ``[R; 0]`` and ``[R^-T J'r; sqrt(|r|^2 - |R^-T J'r|^2)]`` with ``R'R = J'J``
    have the same ``J'J``, ``J'r`` and ``|r|`` as the full rows, so a trust-region solver
    takes the same steps. The normal equations come without the Jacobian's rows
    (:meth:`armaxmodal.modes.refine._SeparableModel.normal_equations`): the nested tests run
    dozens of fits, and their Jacobians are well conditioned in ``(ln omega, xi)``."""

    def __init__(self, model: _SeparableModel):
        self.model = model
        self._x = None

    def _factor(self, x):
        if self._x is None or not np.array_equal(x, self._x):
            gram, grad, power = self.model.normal_equations(x)
            gram = gram + 1e-12 * np.trace(gram) * np.eye(x.size) / x.size  # a null direction stays solvable
            r = scipy.linalg.cholesky(gram, lower=False, check_finite=False)
            top = scipy.linalg.solve_triangular(r, grad, trans="T", check_finite=False)
            last = np.sqrt(max(power - top @ top, 0.0))
            self._x = x.copy()
            self._jac = np.vstack([r, np.zeros((1, x.size))])
            self._res = np.r_[top, last]
        return self._jac, self._res

    def residual(self, x):
        return self._factor(x)[1]

    def jacobian(self, x):
        return self._factor(x)[0]


def _start_vector(data: DftLines, freq_hz, damping, settings: DftSettings):
    w = 2 * np.pi * np.asarray(freq_hz, float)
    nyquist = np.pi / data.dt
    lo_w, n = max(np.abs(data.s[0]), 1e-6), w.size
    lo = np.ravel(np.column_stack([np.full(n, np.log(0.5 * lo_w)), np.full(n, settings.min_damping)]))
    hi = np.ravel(np.column_stack([np.full(n, np.log(nyquist)), np.full(n, settings.max_damping)]))
    start = np.ravel(np.column_stack([np.log(w), np.asarray(damping, float)]))
    return np.clip(start, lo + 1e-9, hi - 1e-9), lo, hi


@single_blas_thread
def fit_modal_model(data: DftLines, freq_hz, damping, hold: str = "bandlimited", max_nfev: int = 40,
                    settings: DftSettings = DEFAULTS.dft) -> ModalModel:  # fmt: skip
    """Fit the modal model with every pole free, from a start.

    Parameters
    ----------
    data : DftLines
        The recording's lines and the sensors' weights.
    freq_hz, damping : (n_modes,) array_like
        Starting frequencies (Hz) and damping ratios.
    hold : {"bandlimited", "zoh"}
        Inter-sample assumption (:mod:`armaxmodal.modes.refine`).
    max_nfev : int
        Cap on residual evaluations.
    settings : DftSettings
        The damping bounds and the stopping tolerance.

    Returns
    -------
    ModalModel
        The fit, its modes by frequency.
    """
    return _fit_modal_model(data, freq_hz, damping, hold, max_nfev, settings)


def _fit_modal_model(data: DftLines, freq_hz, damping, hold: str = "bandlimited", max_nfev: int = 40,
                    settings: DftSettings = DEFAULTS.dft) -> ModalModel:  # fmt: skip
    """:func:`fit_modal_model` itself, under the caller's BLAS threads (the public function holds one)."""
    start, lo, hi = _start_vector(data, freq_hz, damping, settings)
    model = _SeparableModel(data.s, data.z_inv, data.u, data.y, data.dt, hold)
    if 2 * data.s.size < 3 * (4 * start.size // 2 + 2):
        raise OrderError(f"{data.s.size} DFT lines cannot fit {start.size // 2} modes; record longer.")
    compressed = _GramCompressed(model)
    res = scipy.optimize.least_squares(
        compressed.residual, start, jac=compressed.jacobian, bounds=(lo, hi), x_scale="jac", max_nfev=max_nfev,
        ftol=settings.fit_tol, xtol=settings.fit_tol,
    )
    model.residual(res.x)
    coef, resid = model.coef, model.resid
    rss = np.sum(resid**2, axis=0) / data.weights**2  # in the data's units: fits under other weights compare
    n = start.size // 2
    sd = _sandwich_sd(model.sensor_rows(res.x), coef.size + res.x.size)
    lam = _poles(res.x)
    r = (coef[0 : 2 * n : 2] + 1j * coef[1 : 2 * n : 2]).T / data.weights[:, None]
    if hold == "zoh":  # the held residue in z back to the continuous one (as refine_modes)
        mu = np.exp(lam * data.dt)
        r = r * mu * lam / (mu - 1.0)
    model.release()
    f = np.abs(lam) / (2 * np.pi)
    order = np.argsort(f)
    return ModalModel(
        freq_hz=f[order],
        damping=(-lam.real / np.abs(lam))[order],
        freq_sd=(f * sd[0::2])[order],
        damping_sd=sd[1::2][order],
        shapes=(-r / lam**2)[:, order],
        rss=rss,
        n_real=data.n_real,
        hold=hold,
        residual=resid[: data.s.size] + 1j * resid[data.s.size :],
        converged=bool(res.status > 0),  # 0: stopped at max_nfev
    )
