"""Prediction-error method (PEM) for ARMAX models (thesis Section 3.3.2).

Minimises the sum of squared one-step prediction errors ``eps = (A y - q^-nk B u) / C``
over the record. Start: a high-order ARX fit estimates the innovations, then a
Hannan-Rissanen least-squares step gives A, B and C. Then Levenberg-Marquardt with the
exact gradient (regressors filtered through 1/C), keeping C stable by reflecting its roots
into the unit circle.

Two forms:

* per sensor (``shared_poles=False``): one model per output, all driven by the same
  base input -- the thesis's diagonal A (Eqs. 3.11-3.13). Use it to see what each sensor
  shows on its own (the thesis's Table 3.2 with its gaps).
* shared poles (``shared_poles=True``): one A(q) for every sensor, B and C per sensor,
  fitted jointly by maximum likelihood with each channel weighted by its own noise variance
  (the concentrated Gaussian likelihood ``sum_k log V_k``). Physically every sensor sees the
  same poles; pooling them finds heavily damped modes that single sensors miss and gives
  far tighter frequency and damping estimates. Use it for the modal parameters.

Initial conditions are zero (samples before the record count as zero); the loss sums the
errors from the first sample whose regressors all lie inside the record.
"""

from __future__ import annotations

import functools
import warnings
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from armaxmodal._kernels import armax_residual, inverse_filter, lagged_cross, lagged_gram, max_root_radius_below
from armaxmodal._threads import single_blas_thread
from armaxmodal._validate import as_signal_matrix, check_fs, check_not_constant, check_outputs_carry_signal
from armaxmodal.armax import ArmaxModel
from armaxmodal.estimate._gauss_newton import (
    Dense,
    Progress,
    columns,
    inverse,
    levenberg_marquardt,
    normal_equations,
    shared_normal_equations,
    signals,
    solve,
)
from armaxmodal.exceptions import ConvergenceWarning, DataError, OrderError
from armaxmodal.modal import pole_uncertainty
from armaxmodal.recording import Recording
from armaxmodal.stats import Z95

__all__ = ["fit_armax", "ArmaxFit", "covariance_at"]

# At least this many samples per estimated parameter in the fit window.
_MIN_SAMPLES_PER_PARAMETER = 5
# Largest root radius allowed for C (keeps 1/C filtering stable and well conditioned).
_MAX_C_RADIUS = 0.995
_MODE_COLUMNS = [
    "sensor", "freq_hz", "damping", "damped_freq_hz", "freq_ci95_lo", "freq_ci95_hi", "damping_ci95_lo",
    "damping_ci95_hi", "freq_sd", "damping_sd", "pole", "residue", "residue_mag", "residue_phase_deg",
]  # fmt: skip


@dataclass(frozen=True)
class ArmaxFit:
    """Result of :func:`fit_armax`.

    Attributes
    ----------
    models : tuple of ArmaxModel
        One per output sensor (identical A when ``shared_poles``).
    shared_poles : bool
    orders : (na, nb, nc, nk)
    loss : (n_sensors,) ndarray
        Mean squared one-step prediction error over the fit window.
    noise_variance : (n_sensors,) ndarray
        Innovation variance estimate ``V / (N - p)``.
    fit_percent : (n_sensors,) ndarray
        Simulation fit, ``100 (1 - |y - y_sim| / |y - mean y|)`` (NRMSE).
    iterations : (n_sensors,) ndarray of int
        Levenberg-Marquardt iterations (the same number for every sensor when shared).
    converged : (n_sensors,) ndarray of bool
    covariance : tuple of ndarray
        Per sensor, the covariance of ``[a_1..a_na, b (row-major), c_1..c_nc]`` (no c for an
        output-error fit).
    joint_covariance : ndarray or None
        Shared form: covariance of ``[a, b_1, c_1, b_2, c_2, ...]``.
    n_samples : int
        Samples in the fit window.
    """

    models: tuple[ArmaxModel, ...]
    shared_poles: bool
    orders: tuple[int, int, int, int]
    loss: np.ndarray
    noise_variance: np.ndarray
    fit_percent: np.ndarray
    iterations: np.ndarray
    converged: np.ndarray
    covariance: tuple[np.ndarray, ...]
    joint_covariance: np.ndarray | None = None
    n_samples: int = 0
    fs: float = field(default=float("nan"))

    @property
    def sensors(self) -> tuple[str, ...]:
        return tuple(m.output for m in self.models)

    def modes(self, band: tuple[float, float] | None = None) -> pd.DataFrame:
        """One row per sensor and oscillatory pole.

        Columns: sensor, freq_hz, damping, damped_freq_hz, freq_ci95_lo/hi, damping_ci95_lo/hi
        (delta method on the A covariance), residue (complex, first input), residue_mag,
        residue_phase_deg. ``band`` keeps poles whose frequency lies in it (Hz).
        """
        rows = []
        na = self.orders[0]
        for model, cov in zip(self.models, self.covariance, strict=True):
            mu, f, xi, fd = model.modal_parameters()
            sd_f, sd_xi = pole_uncertainty(model.a, mu, cov[:na, :na], model.fs)
            res = model.residues(mu)[0]
            for i in range(mu.size):
                rows.append(
                    {
                        "sensor": model.output,
                        "freq_hz": f[i],
                        "damping": xi[i],
                        "damped_freq_hz": fd[i],
                        "freq_ci95_lo": f[i] - Z95 * sd_f[i],
                        "freq_ci95_hi": f[i] + Z95 * sd_f[i],
                        "damping_ci95_lo": xi[i] - Z95 * sd_xi[i],
                        "damping_ci95_hi": xi[i] + Z95 * sd_xi[i],
                        "freq_sd": sd_f[i],
                        "damping_sd": sd_xi[i],
                        "pole": mu[i],
                        "residue": res[i],
                        "residue_mag": abs(res[i]),
                        "residue_phase_deg": np.degrees(np.angle(res[i])),
                    }
                )
        frame = pd.DataFrame(rows, columns=_MODE_COLUMNS)
        if band is not None and len(frame):
            frame = frame[(frame.freq_hz >= band[0]) & (frame.freq_hz <= band[1])]
        return frame.reset_index(drop=True)

    def to_frame(self) -> pd.DataFrame:
        """One row per sensor: orders, loss, noise variance, fit %, iterations, convergence."""
        na, nb, nc, nk = self.orders
        return pd.DataFrame(
            {
                "sensor": self.sensors,
                "na": na,
                "nb": nb,
                "nc": nc,
                "nk": nk,
                "shared_poles": self.shared_poles,
                "loss": self.loss,
                "noise_variance": self.noise_variance,
                "fit_percent": self.fit_percent,
                "iterations": self.iterations,
                "converged": self.converged,
            }
        )


# -- public entry point -----------------------------------------------------------------
@single_blas_thread
def fit_armax(
    data: Recording | tuple,
    na: int,
    nb: int,
    nc: int,
    nk: int = 0,
    *,
    fs: float | None = None,
    shared_poles: bool = False,
    output_error: bool = False,
    max_iter: int = 100,
    tol: float = 1e-6,
    stop: str = "expected",
    warn: bool = True,
    start: ArmaxFit | None = None,
) -> ArmaxFit:
    """Fit ARMAX models by the prediction-error method.

    Parameters
    ----------
    data : Recording or (u, y)
        A recording, or arrays ``u`` (n_samples,) / (n_samples, n_inputs) and ``y``
        (n_samples,) / (n_samples, n_sensors); then ``fs`` is required.
    na, nb, nc : int
        Orders of A (poles), B (coefficients per input) and C.
    nk : int
        Input delay; 0 for a biproper model with a b0 term, negative for non-causal taps.
    fs : float, optional
        Sampling rate in Hz when arrays are given.
    shared_poles : bool
        One A(q) for all sensors (see the module docstring for when to use which).
    output_error : bool
        Fix ``C = A`` (``nc`` is ignored): ``y = (B/A) u + white noise``, the model of white
        sensor noise. Fewer parameters than ARMAX, so tighter estimates when that noise model
        holds (simulated rides, good sensors); ARMAX when the disturbance is coloured.
    max_iter : int
        Levenberg-Marquardt iteration cap.
    tol : float
        Converged when a full Gauss-Newton step would lower the loss by less than this
        fraction (shared form: the noise-weighted sum over sensors). The default sits far
        below the statistical resolution of the loss (about 1/N), so the estimate is within
        a small fraction of its standard error of the optimum.
    stop : {"expected", "decrease"}
        "expected" applies ``tol`` to the Gauss-Newton step's expected improvement (as
        MATLAB's pem does). "decrease" applies it to the last accepted step's actual decrease:
        cheaper, but a damped step on a flat valley can stop it early -- for sweeps that
        only place poles.
    warn : bool
        Emit :class:`ConvergenceWarning` when the cap is hit.
    start : ArmaxFit, optional
        Continue from this fit of the same data, orders and form instead of computing a
        start: a sweep's fit stopped at a loose ``tol`` is finished for the price of its
        last iterations. ``iterations`` then counts the new ones only.

    Returns
    -------
    ArmaxFit
    """
    return fit_resumable(
        data, (na, nb, nc, nk), fs=fs, shared_poles=shared_poles, output_error=output_error, max_iter=max_iter,
        tol=tol, stop=stop, warn=warn, start=start,
    )[0]  # fmt: skip


def fit_resumable(
    data, orders, *, fs=None, shared_poles=False, output_error=False, max_iter=100, tol=1e-6, stop="expected",
    warn=True, start=None, resume=None, covariance=True,
):  # fmt: skip
    """:func:`fit_armax`'s work, returning ``(fit, checkpoint)``. Shared-pole fits only:
    ``resume`` (the ``checkpoint`` of an earlier fit of the same data, orders and form)
    continues that fit, and ``covariance=False`` leaves the covariances out (empty) for a
    fit judged by its criterion alone; ``checkpoint`` is None for per-sensor fits."""
    if stop not in ("expected", "decrease"):
        raise ValueError(f"stop: expected 'expected' or 'decrease', got {stop!r}.")
    if not shared_poles and (resume is not None or not covariance):
        raise ValueError("resume= and covariance=False apply to shared-pole fits only.")
    if isinstance(max_iter, bool) or not float(max_iter).is_integer() or max_iter < 1:
        raise OrderError(f"max_iter: expected a whole number >= 1, got {max_iter!r}.")
    if not (np.isfinite(tol) and tol > 0):
        raise OrderError(f"tol: expected a finite number > 0, got {tol!r}.")
    u, y, fs, sensors, inputs = _unpack(data, fs)
    na, nb, nc, nk = _check_orders(orders[0], orders[1], 0 if output_error else orders[2], orders[3])
    if abs(nk) > y.shape[0] // 4:
        raise OrderError(
            f"nk = {nk} moves the input by {abs(nk)} of the record's {y.shape[0]} samples ({abs(nk) / fs:g} s): "
            "no modal model has a delay that long. Check the time base, or align the channels first."
        )
    check_outputs_carry_signal(sensors, y)
    # Non-causal taps (nk < 0): y[t] depends on u[t + lead - j]. Pairing y[:n-lead] with
    # u[lead:] gives the equivalent causal model (delay 0) on a window of the record.
    # Filtering by 1/C from rest commutes with delays, not with advances, so this keeps the
    # prediction errors and their gradient exact.
    lead = max(0, -nk)
    y_fit, uT, nk_fit = y[: y.shape[0] - lead], np.ascontiguousarray(u[lead:].T), nk + lead
    t0, t1 = max(na, nc, nk_fit + nb - 1, 0), y_fit.shape[0]
    _check_record_supports(y_fit.shape[0], t1 - t0, (na, nb, nc, nk), u.shape[1], y.shape[1], shared_poles)
    thetas0 = None if start is None else _start_parameters(start, (na, nb, nc, nk), shared_poles, sensors)
    window = (na, nb, nc, nk_fit, t0, t1)
    checkpoint = None
    if shared_poles:
        theta0 = None if thetas0 is None else np.concatenate([thetas0[0][:na]] + [th[na:] for th in thetas0])
        thetas, info, checkpoint = _fit_shared(y_fit, uT, *window, max_iter, tol, output_error, theta0, stop, resume)
        if covariance:
            _shared_covariance(y_fit, uT, *window, info, output_error)
        else:
            del info["state"]
            info["covariance"] = []
    else:
        thetas, info = [], []
        for k in range(y.shape[1]):
            th, inf = _fit_single(
                np.ascontiguousarray(y_fit[:, k]), uT, *window, max_iter, tol, output_error,
                None if thetas0 is None else thetas0[k], stop,
            )  # fmt: skip
            thetas.append(th)
            info.append(inf)
        info = _merge_single_info(info)
    orders = (na, nb, nc, nk)
    fit, valid = _assemble(thetas, info, orders, output_error, u, y, fs, sensors, inputs, t0, lead, shared_poles)
    if warn and not np.all(fit.converged):
        _warn_not_converged(sensors, np.asarray(info["converged"]), valid, max_iter, orders)
    return fit, checkpoint


def _check_record_supports(n, n_eff, orders, n_in, n_out, shared_poles) -> None:
    na, nb, nc, nk = orders
    p_single = na + n_in * nb + nc
    p_needed = p_single if not shared_poles else na + n_out * (n_in * nb + nc)
    if n_eff * (n_out if shared_poles else 1) < _MIN_SAMPLES_PER_PARAMETER * p_needed or n_eff < 2 * p_single:
        raise OrderError(
            f"orders na={na}, nb={nb}, nc={nc}, nk={nk} give {p_needed} parameters; the record has "
            f"{n} samples ({n_eff} usable), too few (need about "
            f"{_MIN_SAMPLES_PER_PARAMETER * p_single} per sensor). Lower the orders or use a longer record."
        )


def _assemble(thetas, info, orders, output_error, u, y, fs, sensors, inputs, t0, lead, shared_poles):
    """The :class:`ArmaxFit` of fitted parameter vectors, and which of its models are valid."""
    na, nb, nc, nk = orders
    models = []
    for k, theta in enumerate(thetas):
        a, b, c = _unpack_theta(theta, na, nb, nc, u.shape[1])
        c = a.copy() if output_error else c
        models.append(ArmaxModel(a, b, c, nk, fs, float(info["noise_variance"][k]), sensors[k], inputs))
    fit_pct = np.array([_nrmse_fit(y[:, k], m.simulate(u), t0, y.shape[0] - lead) for k, m in enumerate(models)])
    # a fit that is not a valid model is never reported as converged: poles on or outside the
    # unit circle (its simulation diverges) or a non-finite loss
    valid = np.array(
        [np.all(np.abs(m.poles()) < 1.0) and np.isfinite(v) for m, v in zip(models, info["loss"], strict=True)]
    )
    fit = ArmaxFit(
        models=tuple(models),
        shared_poles=shared_poles,
        orders=orders,
        loss=info["loss"],
        noise_variance=info["noise_variance"],
        fit_percent=fit_pct,
        iterations=info["iterations"],
        converged=np.asarray(info["converged"]) & valid,
        covariance=tuple(info["covariance"]),
        joint_covariance=info.get("joint_covariance"),
        n_samples=y.shape[0] - lead - t0,
        fs=fs,
    )
    return fit, valid


def _warn_not_converged(sensors, stopped, valid, max_iter, orders) -> None:
    """Say why a fit is flagged converged=False: the iteration cap, or a model that is not
    valid (a pole on or outside the unit circle, a non-finite loss) -- the reasons differ,
    and so do the remedies."""
    capped = [s for s, ok in zip(sensors, stopped, strict=True) if not ok]
    invalid = [s for s, ok, v in zip(sensors, stopped, valid, strict=True) if ok and not v]
    reasons, remedies = [], []
    if capped:
        reasons.append(f"did not converge in {max_iter} iterations for {capped}")
        remedies.append("a larger max_iter or lower orders")
    if invalid:
        reasons.append(f"ended at a pole on or outside the unit circle (its simulation diverges) for {invalid}")
        remedies.append("lower orders or removing a drift (detrend='linear'), which such a pole usually fits")
    warnings.warn(
        f"PEM {' and '.join(reasons)} (orders {','.join(map(str, orders))}); the estimate is flagged "
        f"converged=False. Try {' or '.join(remedies)}.",
        ConvergenceWarning,
        stacklevel=5,  # the caller of fit_armax: _warn, fit_resumable, fit_armax, its BLAS-thread wrapper
    )


@functools.cache
def load_kernels() -> None:
    """Load the compiled kernels into this process with one tiny fit.

    Numba reads them from its on-disk cache at first use, about 0.3 s per process. Called
    before worker processes are forked, so that they inherit the kernels instead of each
    loading them again.
    """
    rng = np.random.default_rng(0)
    u = rng.standard_normal(400)
    y = np.column_stack([np.convolve(u, [1.0, 0.5, 0.2])[:400] + 0.1 * rng.standard_normal(400) for _ in range(2)])
    fit_armax((u, y), 2, 3, 2, -1, fs=100.0, shared_poles=True, max_iter=2, warn=False)


# -- input handling ----------------------------------------------------------------------
def _unpack(data, fs):
    if isinstance(data, Recording):
        return (
            data.base[:, None].copy(),
            np.array(data.response),
            data.fs,
            data.sensors,
            (data.input_name,),
        )
    try:
        u_raw, y_raw = data
    except (TypeError, ValueError) as exc:
        raise DataError("data: expected a Recording or a (u, y) pair of arrays.") from exc
    if fs is None:
        raise DataError("fs: give the sampling rate in Hz when passing arrays (u, y).")
    fs = check_fs(fs)
    u = as_signal_matrix(u_raw, "u", [f"u{m + 1}" for m in range(np.shape(u_raw)[1] if np.ndim(u_raw) == 2 else 1)])
    y = as_signal_matrix(y_raw, "y", [f"y{k + 1}" for k in range(np.shape(y_raw)[1] if np.ndim(y_raw) == 2 else 1)])
    if u.shape[0] != y.shape[0]:
        raise DataError(f"u has {u.shape[0]} samples but y has {y.shape[0]}; trim them to a common length.")
    check_not_constant(u, "input u")
    sensors = tuple(f"y{k + 1}" for k in range(y.shape[1]))
    inputs = tuple(f"u{m + 1}" for m in range(u.shape[1]))
    return u, y, fs, sensors, inputs


def _start_parameters(start, orders, shared_poles, sensors) -> list[np.ndarray]:
    """Per-sensor parameter vectors ``[a, b (row-major), c]`` of a fit to continue from."""
    if not isinstance(start, ArmaxFit):
        raise TypeError(f"start: expected an ArmaxFit, got {type(start).__name__}.")
    if tuple(start.orders) != tuple(orders) or start.shared_poles != shared_poles or start.sensors != tuple(sensors):
        raise OrderError(
            f"start: a fit with orders {tuple(start.orders)}, shared_poles={start.shared_poles} and sensors "
            f"{start.sensors} cannot start one with orders {tuple(orders)}, shared_poles={shared_poles} and "
            f"sensors {tuple(sensors)}; fit again without start."
        )
    nc = orders[2]
    return [np.concatenate([m.a[1:], m.b.ravel(), m.c[1 : nc + 1]]) for m in start.models]


def _check_orders(na, nb, nc, nk):
    vals = {}
    for name, v, lo in (("na", na, 1), ("nb", nb, 1), ("nc", nc, 0), ("nk", nk, None)):
        if isinstance(v, bool) or not float(v).is_integer():
            raise OrderError(f"{name}: expected an integer, got {v!r}.")
        v = int(v)
        if lo is not None and v < lo:
            raise OrderError(f"{name}: expected an integer >= {lo}, got {v}.")
        vals[name] = v
    return vals["na"], vals["nb"], vals["nc"], vals["nk"]


# -- parameter layout ----------------------------------------------------------------------


def _unpack_theta(theta, na, nb, nc, n_in):
    a = np.concatenate([[1.0], theta[:na]])
    b = theta[na : na + n_in * nb].reshape(n_in, nb).copy()
    c = np.concatenate([[1.0], theta[na + n_in * nb :]])
    return a, b, c


def _stable_c(c):
    """Reflect roots of C outside the unit circle inside and cap their radius."""
    if c.size <= 1 or max_root_radius_below(c, _MAX_C_RADIUS):
        return c
    r = np.roots(c)
    mag = np.abs(r)
    r = np.where(mag > 1, 1 / np.conj(np.where(mag > 1, r, 1.0)), r)  # no 1/0 for a root at 0
    mag = np.abs(r)
    r = np.where(mag > _MAX_C_RADIUS, r * (_MAX_C_RADIUS / np.maximum(mag, 1e-300)), r)
    return np.real(np.poly(r))


# -- initial estimate ------------------------------------------------------------------------
def _arx_residual(y, uT, n_h, nb_h, nk, t1):
    """High-order ARX by least squares; returns its residuals (innovation estimates)."""
    n_in = uT.shape[0]
    t0 = max(n_h, nk + nb_h - 1, 0)
    sig = signals(y, uT, np.zeros(y.size))
    cols = columns(n_h, nb_h, 0, nk, n_in)
    g_mat = lagged_gram(sig, *cols, t0, t1)
    g_vec = lagged_cross(sig, *cols, y, t0, t1)
    theta = solve(g_mat, g_vec)
    a, b, c = _unpack_theta(theta, n_h, nb_h, 0, n_in)
    return armax_residual(y, uT, a, b, nk, c)


def _initial_columns_and_signals(y, uT, na, nb, nc, nk, t1):
    n = y.size
    n_h = int(min(max(2 * (na + nc), 20), max(na + nc + 1, (t1 - nk) // 20)))
    e_hat = _arx_residual(y, uT, n_h, nb + n_h // 2, nk, t1) if nc > 0 else np.zeros(n)
    return signals(y, uT, e_hat), columns(na, nb, nc, nk, uT.shape[0])


def _hannan_rissanen(y, uT, na, nb, nc, nk, t0, t1):
    sig, cols = _initial_columns_and_signals(y, uT, na, nb, nc, nk, t1)
    theta = solve(lagged_gram(sig, *cols, t0, t1), lagged_cross(sig, *cols, y, t0, t1))
    return _project(theta, na, nb, nc, uT.shape[0])


def _project(theta, na, nb, nc, n_in, oe=False):
    """Keep C (output error: A) stable inside a parameter vector [a, b, c]."""
    if oe:
        theta = theta.copy()
        theta[:na] = _stable_a(np.concatenate([[1.0], theta[:na]]))[1:]
        return theta
    if nc == 0:
        return theta
    theta = theta.copy()
    start = na + n_in * nb
    theta[start:] = _stable_c(np.concatenate([[1.0], theta[start:]]))[1:]
    return theta


def _stable_a(a):
    """Reflect roots of A outside the unit circle inside (filtering by 1/A must be stable)."""
    if max_root_radius_below(a, 1.0):
        return a
    r = np.roots(a)
    out = np.abs(r) > 1
    r = np.where(out, 1 / np.conj(np.where(out, r, 1.0)), r)
    r = np.where(np.abs(r) >= 0.9999, r * (0.9999 / np.abs(r)), r)
    return np.real(np.poly(r))


def _lagged_sum(uT, b, nk):
    """``sum_m sum_j b[m, j] u_m[t - nk - j]`` for t in [0, n), zero outside the record."""
    n = uT.shape[1]
    out = np.zeros(n)
    for u_m, b_m in zip(uT, b, strict=True):
        full = np.convolve(u_m, b_m)  # full[i] = sum_j b_m[j] u_m[i - j]
        lo, hi = max(nk, 0), min(n, full.size + nk)
        if hi > lo:
            out[lo:hi] += full[lo - nk : hi - nk]
    return out


def _steiglitz_mcbride(ys, uT, a0, na, nb, nk, t0, t1, iterations=6):
    """Output-error start: shared A and per-sensor B by iterated prefiltering with 1/A.

    Each pass solves ``min sum_k w_k |A (y_k / A_prev) - B_k (u / A_prev)|^2`` by linear least
    squares; at the fixed point this is the output-error estimate, the maximum-likelihood
    fit for white sensor noise. Returns ``(a, [b_k])``.
    """
    n_in = uT.shape[0]
    n_out = len(ys)
    cols = columns(na, nb, 0, nk, n_in)
    p_k = n_in * nb
    a = _stable_a(a0)
    weights = np.ones(n_out)
    bs = [np.zeros(p_k)] * n_out
    zeros = np.zeros(uT.shape[1])
    for it in range(iterations):
        g_mat = np.zeros((na + n_out * p_k,) * 2)
        g_vec = np.zeros(na + n_out * p_k)
        # every output and the input through the shared 1/A in one pass (u / A once, not
        # once per sensor)
        filtered = inverse_filter(np.ascontiguousarray(np.vstack([np.vstack(ys), uT])), a)
        if it > 0:
            # reweight by each sensor's output-error residual variance under the previous
            # pass's (A, B_k): y_k - B_k (u / A), which is (A y_k - B_k u) / A without a
            # recursion per sensor
            for k, yk in enumerate(ys):
                e = yk - _lagged_sum(filtered[n_out:], bs[k].reshape(n_in, -1), nk)
                weights[k] = 1.0 / max(float(np.var(e[t0:t1])), 1e-300)
        for k in range(n_out):
            sig = signals(filtered[k], filtered[n_out:], zeros)
            idx = np.concatenate([np.arange(na), na + k * p_k + np.arange(p_k)])
            g_mat[np.ix_(idx, idx)] += weights[k] * lagged_gram(sig, *cols, t0, t1)
            g_vec[idx] += weights[k] * lagged_cross(sig, *cols, sig[0], t0, t1)
        theta = solve(g_mat, g_vec)
        a_new = _stable_a(np.concatenate([[1.0], theta[:na]]))
        bs = [theta[na + k * p_k : na + (k + 1) * p_k] for k in range(n_out)]
        done = np.max(np.abs(a_new - a)) < 1e-4  # a start only: PEM does the rest
        a = a_new
        if done:
            break
    return a, bs


def _subspace_a(ys, uT, na):
    """Monic A(z) of order na from PO-MOESP on all outputs at once (shared poles).

    Past inputs and outputs instrument the future outputs; the column space of the
    projected block Hankel matrix is the extended observability matrix, whose shift
    invariance gives the state matrix. Non-iterative, so it cannot crawl. The block-Hankel
    rows are lagged copies of u and y, so the LQ factor is computed as the Cholesky factor
    of their lagged Gram matrix: O(N p) time and O(p^2) memory instead of a tall QR.
    """
    n_in, n_out = uT.shape[0], len(ys)
    i = max(-(-na // n_out) + 2, 2 * -(-na // n_out), 6)
    sig = np.ascontiguousarray(np.vstack([uT, np.vstack(ys)]))
    n_sig = n_in + n_out
    # kernel column order: each signal with lags 0..2i-1
    col_sig = np.repeat(np.arange(n_sig), 2 * i).astype(np.int64)
    col_lag = np.tile(np.arange(2 * i), n_sig).astype(np.int64)
    gram = lagged_gram(sig, col_sig, col_lag, np.ones(col_sig.size), 2 * i - 1, sig.shape[1])

    def rows(signals, lags):  # Hankel block j of signal s sits at lag 2i-1-j
        return [s * 2 * i + lag for lag in lags for s in signals]

    inputs, outputs = range(n_in), range(n_in, n_sig)
    future, past = [i - 1 - j for j in range(i)], [2 * i - 1 - j for j in range(i)]
    order = rows(inputs, future) + rows(inputs, past) + rows(outputs, past) + rows(outputs, future)
    g = gram[np.ix_(order, order)] / (sig.shape[1] - 2 * i + 1)
    low = np.linalg.cholesky(g + 1e-12 * np.trace(g) / g.shape[0] * np.eye(g.shape[0]))
    mi, li = n_in * i, n_out * i
    l42 = low[2 * mi + li :, mi : 2 * mi + li]
    left, sv, _ = np.linalg.svd(l42, full_matrices=False)
    gamma = left[:, :na] * np.sqrt(sv[:na])
    a_ss = np.linalg.lstsq(gamma[:-n_out], gamma[n_out:], rcond=None)[0]
    return _stable_a(np.real(np.poly(np.linalg.eigvals(a_ss))))


def _output_error_start(ys, uT, theta_hr, na, nb, nc, nk, t0, t1):
    """Parameter vector [a, b_1, c_1, ...]: subspace poles refined by Steiglitz-McBride,
    with C = A where the orders allow (white sensor noise)."""
    n_in = uT.shape[0]
    p_k = n_in * nb + nc
    a, bs = _steiglitz_mcbride(ys, uT, _subspace_a(ys, uT, na), na, nb, nk, t0, t1)
    c = _stable_c(a[: nc + 1] if nc <= na else np.concatenate([a, np.zeros(nc - na)]))[1:]
    parts = [a[1:]]
    for k in range(len(ys)):
        hr_c = theta_hr[na + k * p_k + n_in * nb : na + (k + 1) * p_k]
        parts += [bs[k], c if nc == na else hr_c]
    return np.concatenate(parts)


# -- single-output PEM ------------------------------------------------------------------------
def _residual_and_loss(y, uT, theta, na, nb, nc, nk, t0, t1, oe=False):
    a, b, c = _unpack_theta(theta, na, nb, nc, uT.shape[0])
    if oe:  # output error: C = A, so eps = y - (B / A) u
        c = a
    eps = armax_residual(y, uT, a, b, nk, c)
    with np.errstate(over="ignore", invalid="ignore"):  # an unstable trial step is rejected
        loss = float(eps[t0:t1] @ eps[t0:t1])
    return eps, (loss if np.isfinite(loss) else np.inf), c


def _fit_single(y, uT, na, nb, nc, nk, t0, t1, max_iter, tol, oe=False, theta0=None, stop="expected"):
    n_in = uT.shape[0]
    cols = columns(na, nb, nc, nk, n_in)
    if theta0 is not None:
        theta = _project(theta0, na, nb, nc, n_in, oe)
    else:
        theta = _hannan_rissanen(y, uT, na, nb, nc, nk, t0, t1)
    if oe and theta0 is None:
        try:
            theta = _project(_output_error_start([y], uT, theta, na, nb, nc, nk, t0, t1), na, nb, nc, n_in, oe=True)
        except np.linalg.LinAlgError:  # degenerate input: keep the Hannan-Rissanen start
            theta = _project(theta, na, nb, nc, n_in, oe=True)

    def evaluate(th):
        state = _residual_and_loss(y, uT, th, na, nb, nc, nk, t0, t1, oe)
        return state, state[1]

    def linearise(state):
        return Dense(*normal_equations(y, uT, state[0], state[2], cols, t0, t1, oe))

    state, _ = evaluate(theta)
    unit = state[1] / (t1 - t0)  # 2 log L = -N log V: a unit is a change of V by V / N
    theta, state, it, converged, _ = levenberg_marquardt(
        theta, state, evaluate, linearise, lambda th: _project(th, na, nb, nc, n_in, oe), max_iter, tol, stop, unit
    )
    eps, loss, c = state
    g_mat, _ = normal_equations(y, uT, eps, c, cols, t0, t1, oe)
    n_eff = t1 - t0
    p = theta.size
    lam = loss / max(n_eff - p, 1)
    cov = lam * inverse(g_mat)
    return theta, {
        "loss": loss / n_eff,
        "noise_variance": lam,
        "iterations": it,
        "converged": converged,
        "covariance": cov,
    }


def _merge_single_info(info):
    return {
        "loss": np.array([i["loss"] for i in info]),
        "noise_variance": np.array([i["noise_variance"] for i in info]),
        "iterations": np.array([i["iterations"] for i in info]),
        "converged": np.array([i["converged"] for i in info]),
        "covariance": [i["covariance"] for i in info],
    }


# -- shared-pole PEM -------------------------------------------------------------------------
def _shared_index(k, na, p_k):
    """Global indices of sensor k's local parameters [a, b_k, c_k]."""
    return np.concatenate([np.arange(na), na + k * p_k + np.arange(p_k)])


def _local(theta, k, na, p_k):
    return theta[_shared_index(k, na, p_k)]


def _shared_start(ys, uT, na, nb, nc, nk, t0, t1, oe, evaluate):
    """The more likely of a joint Hannan-Rissanen and a subspace/Steiglitz-McBride start:
    ``(theta, state, losses)``."""
    n_out, n_in = len(ys), uT.shape[0]
    p_k = n_in * nb + nc
    cols = columns(na, nb, nc, nk, n_in)
    # Joint Hannan-Rissanen start, each sensor weighted by its ARX innovation variance.
    p = na + n_out * p_k
    g_mat = np.zeros((p, p))
    g_vec = np.zeros(p)
    for k in range(n_out):
        sig, _ = _initial_columns_and_signals(ys[k], uT, na, nb, nc, nk, t1)
        w = 1.0 / max(float(np.var(sig[-1, t0:t1])) if nc else float(np.var(ys[k][t0:t1])), 1e-300)
        idx = _shared_index(k, na, p_k)
        g_mat[np.ix_(idx, idx)] += w * lagged_gram(sig, *cols, t0, t1)
        g_vec[idx] += w * lagged_cross(sig, *cols, ys[k], t0, t1)
    theta = _project_shared(solve(g_mat, g_vec), na, nb, nc, n_in, n_out, oe)

    state, losses = evaluate(theta)
    # Second start: output error by Steiglitz-McBride; keep whichever is more likely. A
    # degenerate input (one sinusoid) can leave the subspace step without a Cholesky factor,
    # and at very high orders its iterations can diverge to non-finite values (ValueError
    # from the factorisation): then the first start stands alone.
    try:
        alt = _project_shared(_output_error_start(ys, uT, theta, na, nb, nc, nk, t0, t1), na, nb, nc, n_in, n_out, oe)
    except (np.linalg.LinAlgError, ValueError):
        alt = None
    if alt is not None:
        state_alt, losses_alt = evaluate(alt)
        if np.sum(np.log(losses_alt)) < np.sum(np.log(losses)):
            theta, state, losses = alt, state_alt, losses_alt
    return theta, state, losses


@dataclass(frozen=True)
class _Checkpoint:
    """Where a shared-pole fit stopped: enough to continue it bit for bit as if its
    iteration cap had been higher (``fit_resumable(..., resume=)``). The sweep continues the delay
    choice's short fits instead of starting them again."""

    theta: np.ndarray
    variances: np.ndarray  # the noise variances weighting the next iterations
    iterations: int  # done before the Levenberg-Marquardt run in progress
    progress: Progress | None  # that run's state; None between runs
    converged: bool  # stopped by the rule: nothing is left to do


def _fit_shared(y, uT, na, nb, nc, nk, t0, t1, max_iter, tol, oe=False, theta0=None, stop="expected", resume=None):
    """Joint maximum likelihood with per-sensor noise variances.

    Alternates a weighted least-squares Levenberg-Marquardt solve at fixed variances
    (a true Gauss-Newton problem, so it converges fast) with the variance update
    ``lambda_k = V_k / N``; at the fixed point this maximises the concentrated likelihood
    ``-N/2 sum_k log V_k``. Gauss-Newton on ``sum_k log V_k`` directly would drop a Hessian
    term that does not vanish at the optimum and crawl. ``resume`` (a :class:`_Checkpoint`)
    continues a fit instead of starting one. Returns ``(thetas, info, checkpoint)``; ``info``
    lacks the covariances, which :func:`_shared_covariance` adds.
    """
    n_out = y.shape[1]
    n_in = uT.shape[0]
    p_k = n_in * nb + nc
    cols = columns(na, nb, nc, nk, n_in)
    ys = [np.ascontiguousarray(y[:, k]) for k in range(n_out)]
    n_eff = t1 - t0

    def evaluate(th):
        out = [_residual_and_loss(ys[k], uT, _local(th, k, na, p_k), na, nb, nc, nk, t0, t1, oe) for k in range(n_out)]
        return out, np.array([o[1] for o in out])

    if resume is not None:
        theta, variances, total_iterations = resume.theta, resume.variances, resume.iterations
        progress, converged = resume.progress, resume.converged
        state, losses = evaluate(theta)
    else:
        if theta0 is not None:
            theta = _project_shared(theta0, na, nb, nc, n_in, n_out, oe)
            state, losses = evaluate(theta)
        else:
            theta, state, losses = _shared_start(ys, uT, na, nb, nc, nk, t0, t1, oe, evaluate)
        variances, total_iterations, progress, converged = losses / n_eff, 0, None, False
    paused = None
    while not converged and total_iterations < max_iter:
        weights = 1.0 / variances

        def weighted(th, weights=weights):
            per_sensor, losses_t = evaluate(th)
            with np.errstate(invalid="ignore", over="ignore"):  # an unstable trial (inf loss) is rejected
                return (per_sensor, losses_t), float(weights @ losses_t)

        def linearise(st, variances=variances):
            return shared_normal_equations(ys, uT, st[0], variances, cols, na, p_k, t0, t1, oe)

        theta, (state, losses), used, inner_converged, progress = levenberg_marquardt(
            theta,
            (state, losses),
            weighted,
            linearise,
            lambda th: _project_shared(th, na, nb, nc, n_in, n_out, oe),
            max_iter - total_iterations,
            tol,
            stop,
            1.0,  # the objective sum_k V_k / lambda_k changes with 2 log L one for one
            progress,
        )
        if progress is not None:  # the cap stopped this run mid-way: continue it from here
            paused = _Checkpoint(theta, variances, total_iterations, progress, False)
            progress = None
        total_iterations += used
        new_variances = losses / n_eff
        settled = np.max(np.abs(new_variances / variances - 1.0)) < 1e-3
        variances = new_variances
        converged = inner_converged and settled
    checkpoint = paused or _Checkpoint(theta, variances, total_iterations, None, converged)
    info = {
        "loss": losses / n_eff,
        "noise_variance": losses / max(n_eff - (na / n_out + p_k), 1),
        "iterations": np.full(n_out, total_iterations),
        "converged": np.full(n_out, converged),
        "state": state,
    }
    return [_local(theta, k, na, p_k) for k in range(n_out)], info, checkpoint


def _shared_covariance(y, uT, na, nb, nc, nk, t0, t1, info, oe=False):
    """Add the joint and per-sensor covariances to a shared fit's ``info`` (in place)."""
    n_out, p_k = y.shape[1], uT.shape[0] * nb + nc
    ys = [np.ascontiguousarray(y[:, k]) for k in range(n_out)]
    cols = columns(na, nb, nc, nk, uT.shape[0])
    lam = info["noise_variance"]
    joint = inverse(shared_normal_equations(ys, uT, info.pop("state"), lam, cols, na, p_k, t0, t1, oe).full())
    info["covariance"] = [joint[np.ix_(_shared_index(k, na, p_k), _shared_index(k, na, p_k))] for k in range(n_out)]
    info["joint_covariance"] = joint


def _project_shared(theta, na, nb, nc, n_in, n_out, oe=False):
    if oe:
        return _project(theta, na, nb, nc, n_in, oe=True)
    if nc == 0:
        return theta
    theta = theta.copy()
    p_k = n_in * nb + nc
    for k in range(n_out):
        start = na + k * p_k + n_in * nb
        theta[start : start + nc] = _stable_c(np.concatenate([[1.0], theta[start : start + nc]]))[1:]
    return theta


def _nrmse_fit(y, y_sim, t0, t1):
    """NRMSE fit in percent; NaN when the model is unstable and its simulation diverges."""
    with np.errstate(over="ignore", invalid="ignore"):
        err = np.sqrt(np.sum((y[t0:t1] - y_sim[t0:t1]) ** 2))
    if not np.isfinite(err):
        return float("nan")
    ref = np.linalg.norm(y[t0:t1] - y[t0:t1].mean())
    return 100.0 * (1.0 - err / ref) if ref > 0 else float("nan")


def covariance_at(
    models,
    data: Recording | tuple,
    *,
    fs: float | None = None,
    shared_poles: bool = False,
    output_error: bool = False,
) -> list[np.ndarray]:
    """Asymptotic covariance of the PEM estimate evaluated at given models.

    At the true system with Gaussian innovations this is the Cramer-Rao bound: the
    smallest covariance any unbiased estimator can reach on this record.

    Parameters
    ----------
    models : sequence of ArmaxModel
        One per sensor, with ``noise_variance`` set (identical A when ``shared_poles``).
    data : Recording or (u, y)
        The input and outputs that drive the gradient (use noise-free or measured data).
    shared_poles : bool
        Pool the A parameters over sensors as :func:`fit_armax` does.
    output_error : bool
        The output-error parametrisation ``[a, b]`` with ``C = A`` fixed.

    Returns
    -------
    list of ndarray
        Per sensor, the covariance of ``[a_1..a_na, b (row-major), c_1..c_nc]``.
    """
    u, y, _, _, _ = _unpack(data, fs)
    na, nb, nc, nk = models[0].orders
    nc = 0 if output_error else nc
    lead = max(0, -nk)
    y_fit, u_fit, nk_fit = y[: y.shape[0] - lead], u[lead:], nk + lead
    n = y_fit.shape[0]
    t0, t1 = max(na, nc, nk_fit + nb - 1, 0), n
    uT = np.ascontiguousarray(u_fit.T)
    n_in = uT.shape[0]
    cols = columns(na, nb, nc, nk_fit, n_in)
    blocks = []
    for k, m in enumerate(models):
        yk = np.ascontiguousarray(y_fit[:, k])
        theta = np.concatenate([m.a[1:], m.b.ravel(), m.c[1 : nc + 1]])
        eps, _, c = _residual_and_loss(yk, uT, theta, na, nb, nc, nk_fit, t0, t1, output_error)
        blocks.append(normal_equations(yk, uT, eps, c, cols, t0, t1, output_error)[0] / m.noise_variance)
    if not shared_poles:
        return [inverse(g) for g in blocks]
    p_k = n_in * nb + nc
    g_mat = np.zeros((na + len(models) * p_k,) * 2)
    for k, g in enumerate(blocks):
        idx = _shared_index(k, na, p_k)
        g_mat[np.ix_(idx, idx)] += g
    joint = inverse(g_mat)
    return [joint[np.ix_(_shared_index(k, na, p_k), _shared_index(k, na, p_k))] for k in range(len(models))]
