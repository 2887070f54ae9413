"""The prediction-error fit of ARMAX models (thesis Section 3.3.2): :func:`~armaxmodal.fit_armax`, the
public call, validates the data and the orders, picks the start, runs the Levenberg-Marquardt
loop of :mod:`armaxmodal.estimate.pem` per sensor or with the poles shared, and assembles the
:class:`~armaxmodal.estimate.result.ArmaxFit`.
"""

from __future__ import annotations

import functools
import warnings

import numpy as np

from armaxmodal._threads import single_blas_thread
from armaxmodal._validate import as_signal_matrix, check_fs, check_not_constant, check_outputs_carry_signal
from armaxmodal.armax import ArmaxModel
from armaxmodal.estimate._gauss_newton import (
    columns,
    inverse,
    normal_equations,
)
from armaxmodal.estimate.parameters import shared_index, unpack_theta
from armaxmodal.estimate.pem import fit_shared, fit_single, merge_single_info, residual_and_loss, shared_covariance
from armaxmodal.estimate.result import ArmaxFit
from armaxmodal.exceptions import ConvergenceWarning, DataError, OrderError
from armaxmodal.recording import Recording

__all__ = ["fit_armax", "fit_resumable", "covariance_at", "load_kernels", "record_supports"]

# At least this many samples per estimated parameter in the fit window.
_MIN_SAMPLES_PER_PARAMETER = 5


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
        last iterations. ``iterations`` then counts the new ones only. A shared-pole fit of
        the same orders also starts a per-sensor fit of any of its sensors: from its A and
        that sensor's B and C.

    Returns
    -------
    ArmaxFit

    See Also
    --------
    armaxmodal.choose_orders : Choose the orders by an information criterion.
    armaxmodal.identify : One model's modes, checked against the measured FRF.
    armaxmodal.stabilisation_diagram : Fits over a range of orders.

    Examples
    --------
    >>> import numpy as np
    >>> import armaxmodal as am
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 120.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)
    >>> fit = am.fit_armax(ride, 8, 8, 8, 0, shared_poles=True)  # na, nb, nc, nk
    >>> fit.orders
    (8, 8, 8, 0)
    >>> round(float(fit.fit_percent.min()))  # the worst output's one-step fit, %
    97
    """
    return fit_resumable(
        data,
        (na, nb, nc, nk),
        fs=fs,
        shared_poles=shared_poles,
        output_error=output_error,
        max_iter=max_iter,
        tol=tol,
        stop=stop,
        warn=warn,
        start=start,
    )[0]


def fit_resumable(
    data,
    orders,
    *,
    fs=None,
    shared_poles=False,
    output_error=False,
    max_iter=100,
    tol=1e-6,
    stop="expected",
    warn=True,
    start=None,
    resume=None,
    covariance=True,
):
    """:func:`~armaxmodal.fit_armax`'s work, returning ``(fit, checkpoint)``. Shared-pole fits only:
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
        thetas, info, checkpoint = fit_shared(y_fit, uT, *window, max_iter, tol, output_error, theta0, stop, resume)
        if covariance:
            shared_covariance(y_fit, uT, *window, info, output_error)
        else:
            del info["state"]
            info["covariance"] = []
    else:
        thetas, info = [], []
        for k in range(y.shape[1]):
            th, inf = fit_single(
                np.ascontiguousarray(y_fit[:, k]),
                uT,
                *window,
                max_iter,
                tol,
                output_error,
                None if thetas0 is None else thetas0[k],
                stop,
            )
            thetas.append(th)
            info.append(inf)
        info = merge_single_info(info)
    orders = (na, nb, nc, nk)
    fit, valid = _assemble(thetas, info, orders, output_error, u, y, fs, sensors, inputs, t0, lead, shared_poles)
    if warn and not np.all(fit.converged):
        _warn_not_converged(sensors, np.asarray(info["converged"]), valid, max_iter, orders)
    return fit, checkpoint


def record_supports(n: int, orders: tuple[int, int, int, int], n_in: int, n_out: int, shared_poles: bool) -> bool:
    """Can ``n`` samples hold a fit of ``orders``? The rule :func:`fit_armax` refuses by: at least
    5 samples per parameter, and twice one sensor's parameters, in the samples its start-up leaves.

    Parameters
    ----------
    n : int
        Samples of the window fitted.
    orders : (na, nb, nc, nk)
    n_in, n_out : int
        Inputs and outputs.
    shared_poles : bool
        One A for every output (its parameters counted once).

    Returns
    -------
    bool
    """
    na, nb, nc, nk = orders
    lead = max(0, -nk)
    return _supported(n - lead - max(na, nc, nk + lead + nb - 1, 0), orders, n_in, n_out, shared_poles)


def _supported(n_eff, orders, n_in, n_out, shared_poles) -> bool:
    na, nb, nc, _ = orders
    p_single = na + n_in * nb + nc
    p_needed = p_single if not shared_poles else na + n_out * (n_in * nb + nc)
    return n_eff * (n_out if shared_poles else 1) >= _MIN_SAMPLES_PER_PARAMETER * p_needed and n_eff >= 2 * p_single


def _check_record_supports(n, n_eff, orders, n_in, n_out, shared_poles) -> None:
    na, nb, nc, nk = orders
    p_single = na + n_in * nb + nc
    p_needed = p_single if not shared_poles else na + n_out * (n_in * nb + nc)
    if not _supported(n_eff, orders, n_in, n_out, shared_poles):
        raise OrderError(
            f"orders na={na}, nb={nb}, nc={nc}, nk={nk} give {p_needed} parameters; the record has "
            f"{n} samples ({n_eff} usable), too few (need about "
            f"{_MIN_SAMPLES_PER_PARAMETER * p_single} per sensor). Lower the orders or use a longer record."
        )


def _assemble(thetas, info, orders, output_error, u, y, fs, sensors, inputs, t0, lead, shared_poles):
    """The :class:`~armaxmodal.ArmaxFit` of fitted parameter vectors, and which of its models are valid."""
    na, nb, nc, nk = orders
    models = []
    for k, theta in enumerate(thetas):
        a, b, c = unpack_theta(theta, na, nb, nc, u.shape[1])
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
    before the worker threads start, so that they do not all wait on numba's lock to load
    the same kernels.
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
    nc = orders[2]
    from_shared = start.shared_poles and not shared_poles and set(sensors) <= set(start.sensors)
    if from_shared and tuple(start.orders) == tuple(orders):
        # a shared-pole fit starts each sensor's own model: its A, and that sensor's B and C
        models = [start.models[start.sensors.index(s)] for s in sensors]
        return [np.concatenate([m.a[1:], m.b.ravel(), m.c[1 : nc + 1]]) for m in models]
    if tuple(start.orders) != tuple(orders) or start.shared_poles != shared_poles or start.sensors != tuple(sensors):
        raise OrderError(
            f"start: a fit with orders {tuple(start.orders)}, shared_poles={start.shared_poles} and sensors "
            f"{start.sensors} cannot start one with orders {tuple(orders)}, shared_poles={shared_poles} and "
            f"sensors {tuple(sensors)}; fit again without start."
        )
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
        Pool the A parameters over sensors as :func:`~armaxmodal.fit_armax` does.
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
        eps, _, c = residual_and_loss(yk, uT, theta, na, nb, nc, nk_fit, t0, t1, output_error)
        blocks.append(normal_equations(yk, uT, eps, c, cols, t0, t1, output_error)[0] / m.noise_variance)
    if not shared_poles:
        return [inverse(g) for g in blocks]
    p_k = n_in * nb + nc
    g_mat = np.zeros((na + len(models) * p_k,) * 2)
    for k, g in enumerate(blocks):
        idx = shared_index(k, na, p_k)
        g_mat[np.ix_(idx, idx)] += g
    joint = inverse(g_mat)
    return [joint[np.ix_(shared_index(k, na, p_k), shared_index(k, na, p_k))] for k in range(len(models))]
