"""The model the diagnosis refits: ARMAX plus the effects added to it.

An effect is added without touching the numba fitter:

* channel shifts (a late sensor or input) move that channel by a fractional number of
  samples before the fit (Fourier shift: the data are band-limited);
* additive output disturbances ``y = G u + H e + phi theta`` (offset, drift, sinusoids) are
  estimated by backfitting: fit ARMAX to ``y - phi theta``, then ``theta`` by least squares
  of the one-step errors on the regressors filtered by ``A / C`` -- exact GLS for ``theta``
  given the dynamics, so three passes converge;
* a richer noise model raises ``nc``.

Held-out errors (see :func:`held_out`) come from two blocked folds: a model fitted on one half
of the record predicts the other half. Its one-step predictions there use the measured past,
so no start-up transient enters; only the parameters come from the other half.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from scipy.signal import lfilter

from ..fit import ArmaxFit, fit_armax

__all__ = ["Signals", "ModelSpec", "FittedModel", "fit_model", "held_out", "HeldOut"]

#: Backfitting passes between the ARMAX fit and the disturbance coefficients.
BACKFIT_PASSES = 3
#: Iteration cap of each refit (the baseline's parameters are the start of every refit).
MAX_ITER = 40


@dataclass(frozen=True)
class Signals:
    """The record as the diagnosis sees it: ``u`` (n,), ``y`` (n, K), names, fs in Hz."""

    u: np.ndarray
    y: np.ndarray
    fs: float
    sensors: tuple[str, ...]
    input_name: str

    @property
    def n(self) -> int:
        return self.u.size


@dataclass(frozen=True)
class ModelSpec:
    """What the model holds beyond the baseline ARMAX.

    Attributes
    ----------
    orders : (na, nb, nc, nk)
    shifts : tuple of (channel, samples)
        Channel moved earlier by this many samples (positive: it was recorded late).
    trend_degree : int
        -1 none, 0 an offset per sensor, 1 offset and drift, 2 with a quadratic term.
    lines_hz : tuple of float
        Sinusoidal disturbances (a sine and a cosine per sensor each).
    extra_nc : int
        C coefficients beyond ``orders``'s nc.
    """

    orders: tuple[int, int, int, int]
    shifts: tuple[tuple[str, float], ...] = ()
    trend_degree: int = -1
    lines_hz: tuple[float, ...] = ()
    extra_nc: int = 0

    @property
    def n_disturbance(self) -> int:
        return self.trend_degree + 1 + 2 * len(self.lines_hz)

    def n_parameters(self, n_sensors: int) -> int:
        na, nb, nc, _ = self.orders
        return na + n_sensors * (nb + nc + self.extra_nc + self.n_disturbance)


def disturbance_columns(spec: ModelSpec, n: int, fs: float) -> np.ndarray:
    """Regressors of the additive disturbances, (n, q): ``[1, tau, tau^2][:degree+1]`` with
    ``tau`` the time scaled to [-1, 1], then ``sin, cos`` of each line."""
    tau = np.linspace(-1.0, 1.0, n)
    cols = [tau**d for d in range(spec.trend_degree + 1)]
    t = np.arange(n) / fs
    for f in spec.lines_hz:
        cols += [np.sin(2 * np.pi * f * t), np.cos(2 * np.pi * f * t)]
    return np.column_stack(cols) if cols else np.zeros((n, 0))


def fractional_shift(x: np.ndarray, samples: float) -> np.ndarray:
    """``x`` moved earlier by ``samples`` (may be fractional): ``out[t] = x[t + samples]``.

    A Fourier shift, exact for band-limited data; the record is mirrored first so the wrap
    at the ends stays small (the edges are excluded from every error anyway).
    """
    if samples == 0:
        return x.copy()
    n = x.size
    ext = np.concatenate([x, x[::-1]])
    f = np.fft.rfftfreq(ext.size)
    return np.fft.irfft(np.fft.rfft(ext) * np.exp(2j * np.pi * f * samples), ext.size)[:n]


def apply_shifts(signals: Signals, shifts) -> Signals:
    """Signals with each named channel (an output or the input) moved by its shift."""
    u, y = signals.u, signals.y.copy()
    for name, s in shifts:
        if name == signals.input_name:
            u = fractional_shift(u, s)
        else:
            k = signals.sensors.index(name)
            y[:, k] = fractional_shift(y[:, k], s)
    return replace(signals, u=u, y=y)


@dataclass(frozen=True)
class FittedModel:
    """A :class:`ModelSpec` fitted on ``window`` of the (shifted) signals.

    ``theta`` is (q, K): disturbance coefficients per sensor, ``theta_cov`` (K, q, q).
    """

    spec: ModelSpec
    fit: ArmaxFit
    theta: np.ndarray
    theta_cov: np.ndarray
    window: tuple[int, int]
    signals: Signals = field(repr=False)

    def disturbance(self) -> np.ndarray:
        """The fitted disturbance on every sample, (n, K)."""
        phi = disturbance_columns(self.spec, self.signals.n, self.signals.fs)
        return phi @ self.theta

    def one_step_errors(self) -> np.ndarray:
        """One-step prediction errors on the whole record, (n, K)."""
        s, d = self.signals, self.disturbance()
        return np.column_stack(
            [m.prediction_errors(s.y[:, k] - d[:, k], s.u) for k, m in enumerate(self.fit.models)]
        )

    def simulation_errors(self) -> np.ndarray:
        """Output minus the noise-free simulated response (and the disturbance), (n, K)."""
        s, d = self.signals, self.disturbance()
        return np.column_stack([s.y[:, k] - d[:, k] - m.simulate(s.u) for k, m in enumerate(self.fit.models)])

    def simulated(self) -> np.ndarray:
        """The noise-free response to the input, (n, K)."""
        return np.column_stack([m.simulate(self.signals.u) for m in self.fit.models])


def usable(n: int, spec: ModelSpec) -> np.ndarray:
    """Samples where every error is meaningful: away from start-up, non-causal taps and shift
    edges, (n,) bool."""
    na, nb, nc, nk = spec.orders
    shift = max((abs(s) for _, s in spec.shifts), default=0.0)
    head = max(na, nc + spec.extra_nc, nk + nb - 1, n // 50) + int(np.ceil(shift)) + 8
    tail = max(0, -nk) + int(np.ceil(shift)) + 8
    mask = np.zeros(n, bool)
    mask[head : n - tail] = True
    return mask


def fit_model(
    spec: ModelSpec, signals: Signals, window: tuple[int, int] | None = None, start: FittedModel | None = None
) -> FittedModel:
    """Fit ``spec`` on ``window`` (default: the whole record) of ``signals`` (unshifted)."""
    shifted = apply_shifts(signals, spec.shifts)
    lo, hi = window or (0, signals.n)
    na, nb, nc, nk = spec.orders
    phi = disturbance_columns(spec, signals.n, signals.fs)
    k_count = len(signals.sensors)
    cov = np.zeros((k_count, phi.shape[1], phi.shape[1]))
    u, y = shifted.u[lo:hi], shifted.y[lo:hi]
    # start from plain least squares of the output on the regressors: the response to a
    # zero-mean broadband input is nearly orthogonal to an offset, a trend or a line, and an
    # ARMAX fitted with the disturbance left in would carry it in its poles (a root near 1)
    theta = np.linalg.lstsq(phi[lo:hi], y, rcond=None)[0] if phi.shape[1] else np.zeros((0, k_count))
    fit = start.fit if start is not None and start.spec == spec else None
    passes = BACKFIT_PASSES if phi.shape[1] else 1
    for _ in range(passes):
        fit = fit_armax(
            (u, y - phi[lo:hi] @ theta),
            na,
            nb,
            nc + spec.extra_nc,
            nk,
            fs=signals.fs,
            shared_poles=True,
            max_iter=MAX_ITER,
            warn=False,
            start=fit,
        )
        if phi.shape[1]:
            theta, cov = _disturbance_gls(fit, u, y, phi[lo:hi], spec)
    return FittedModel(spec, fit, theta, cov, (lo, hi), shifted)


def _disturbance_gls(fit: ArmaxFit, u, y, phi, spec):
    """Disturbance coefficients given the dynamics: one-step errors of ``y`` regressed on the
    regressors filtered by ``A / C`` (the errors are linear in them)."""
    mask = usable(u.size, spec)
    q = phi.shape[1]
    theta = np.zeros((q, len(fit.models)))
    cov = np.zeros((len(fit.models), q, q))
    for k, m in enumerate(fit.models):
        eps0 = m.prediction_errors(y[:, k], u)
        z = lfilter(m.a, m.c, phi, axis=0)
        coef, *_ = np.linalg.lstsq(z[mask], eps0[mask], rcond=None)
        resid = eps0[mask] - z[mask] @ coef
        sigma2 = float(resid @ resid) / max(1, mask.sum() - q)
        theta[:, k] = coef
        cov[k] = sigma2 * np.linalg.pinv(z[mask].T @ z[mask])
    return theta, cov


@dataclass(frozen=True)
class HeldOut:
    """Errors on data the parameters were not fitted to (two blocked folds).

    Attributes
    ----------
    one_step : (n, K) ndarray
        One-step prediction errors; each half predicted by the model of the other half.
    simulation : (n, K) ndarray
        Simulation errors, likewise.
    mask : (n,) bool ndarray
        Samples that count.
    """

    one_step: np.ndarray
    simulation: np.ndarray
    mask: np.ndarray

    def rms(self) -> np.ndarray:
        """Held-out one-step RMS error per sensor."""
        e = self.one_step[self.mask]
        return np.sqrt(np.mean(e**2, axis=0))

    def fit_percent(self, y: np.ndarray) -> np.ndarray:
        """Held-out simulation fit (NRMSE, %) per sensor."""
        e, yy = self.simulation[self.mask], y[self.mask]
        return 100 * (1 - np.linalg.norm(e, axis=0) / np.linalg.norm(yy - yy.mean(axis=0), axis=0))


def held_out(spec: ModelSpec, signals: Signals, start: FittedModel | None = None) -> HeldOut:
    """Fit on each half, predict the other (see the module docstring)."""
    n = signals.n
    half = n // 2
    one = np.zeros((n, len(signals.sensors)))
    sim = np.zeros_like(one)
    for fit_window, test in (((0, half), slice(half, n)), ((half, n), slice(0, half))):
        model = fit_model(spec, signals, fit_window, start)
        one[test] = model.one_step_errors()[test]
        sim[test] = model.simulation_errors()[test]
    return HeldOut(one, sim, usable(n, spec))
