"""The model the diagnosis refits: ARMAX plus the effects added to it.

An effect is added without touching the numba fitter:

* channel shifts (a late sensor or input) move that channel by a fractional number of
  samples before the fit (Fourier shift: the data are band-limited), and a clock's drift
  resamples it on its own time axis (the same interpolation, evaluated by a chirp-z transform);
* additive output disturbances ``y = G u + H e + phi theta`` (offset, drift, sinusoids) are
  estimated by backfitting: ``theta`` from least squares of the output on the regressors,
  ARMAX fitted to ``y - phi theta``, ``theta`` again from the simulation residual, three
  passes (see ``_disturbance_ls`` for why not GLS);
* a richer noise model raises ``nc``;
* a clipped output's samples at its rail, and a faulty sensor's stuck or glitched samples,
  are treated as missing: filled by the model's one-step prediction and refitted (a few
  passes), and left out of every error (:mod:`.clipping`, :mod:`.faults`).

Held-out errors (see ``held_out``) come from two blocked folds: a model fitted on one half
of the record predicts the other half. Its one-step predictions there use the measured past,
so no start-up transient enters; only the parameters come from the other half.

One module of about 550 lines on purpose: the plain and the piecewise model are fitted and
held out through the same interface (``fit_model``, ``held_out``, ``HeldOut``), which every
effect's test and fix calls; apart, the two would have to be kept in step by hand.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from scipy.signal import czt, lfilter

from armaxmodal.diagnosis.clipping import IMPUTE_PASSES, clipped_mask, fill_by_prediction
from armaxmodal.estimate.fit import fit_armax
from armaxmodal.estimate.result import ArmaxFit
from armaxmodal.modes.settings import DEFAULTS

__all__ = ["Signals", "ModelSpec", "FittedModel", "fit_model", "held_out", "HeldOut", "counted", "as_inputs"]

#: Lags of a nonlinear term in its score test.
TERM_LAGS = 3
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
    #: Named extra inputs (n,) a spec's ``terms`` refer to (nonlinear terms).
    extra: dict = field(default_factory=dict, compare=False, repr=False)

    @property
    def n(self) -> int:
        return self.u.size

    def inputs(self, spec: ModelSpec) -> np.ndarray:
        """The measured input and the spec's extra inputs, (n, 1 + len(spec.terms))."""
        return np.column_stack([self.u] + [self.extra[name] for name in spec.terms])


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
    terms : tuple of str
        Names of extra inputs in :attr:`Signals.extra` (a nonlinear term of the simulated
        response): each enters through the dynamics like the base input, ``B_m / A``.
    clipped : tuple of str
        Clipped outputs.
    faults : tuple of (str, tuple of int)
        Outputs with stuck or glitched samples, and those samples.
    inputs_from : tuple of str
        Recorded channels that are inputs, not outputs (a second excitation): taken out of the
        outputs and entered as extra inputs (also listed in ``terms``).
    steps : tuple of (str, int, float)
        Level shifts taken out of an output: from this sample on (recorded frame) its offset is
        larger by this much (the channel's units), as a sensor knocked or re-zeroed leaves it.
    gains : tuple of (str, int, float)
        Gain changes taken out of an output: from this sample on it reads this factor times what
        reaches it (a range switch, a loosening mount). Recorded = factor x true + step.
    drifts : tuple of (str, float)
        Clock drifts taken out of a channel (an output or the input): its delay grows by this many
        samples per sample (its clock runs slow by that fraction), taken out about the record's
        middle so the mean delay stays where the shifts and ``nk`` put it.
    """

    orders: tuple[int, int, int, int]
    shifts: tuple[tuple[str, float], ...] = ()
    trend_degree: int = -1
    lines_hz: tuple[float, ...] = ()
    extra_nc: int = 0
    terms: tuple[str, ...] = ()
    #: Outputs whose samples at a rail are filled from the model and left out of errors.
    clipped: tuple[str, ...] = ()
    #: (output, sample indices) a sensor fault spoiled: filled and left out likewise.
    faults: tuple[tuple[str, tuple[int, ...]], ...] = ()
    inputs_from: tuple[str, ...] = ()
    steps: tuple[tuple[str, int, float], ...] = ()
    gains: tuple[tuple[str, int, float], ...] = ()
    drifts: tuple[tuple[str, float], ...] = ()

    @property
    def n_disturbance(self) -> int:
        return self.trend_degree + 1 + 2 * len(self.lines_hz)

    def n_parameters(self, n_sensors: int) -> int:
        na, nb, nc, _ = self.orders
        n_in = 1 + len(self.terms)
        return na + n_sensors * (n_in * nb + nc + self.extra_nc + self.n_disturbance)


def disturbance_columns(spec: ModelSpec, signals: Signals) -> np.ndarray:
    """Regressors of the additive disturbances, (n, q): ``[1, tau, tau^2][:degree+1]`` with
    ``tau`` the time scaled to [-1, 1], then ``sin, cos`` of each line."""
    n, fs = signals.n, signals.fs
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


def moved(x: np.ndarray, samples: float = 0.0, rate: float = 0.0) -> np.ndarray:
    """``x`` moved earlier by ``samples`` and its clock's drift ``rate`` taken out:
    ``out[t] = x[t + samples + rate (t - c)]``, ``c`` the record's middle.

    The band-limited (Fourier) interpolation of the mirrored record, as :func:`fractional_shift`,
    evaluated on the new times by a chirp-z transform: they are equally spaced, ``1 + rate`` apart,
    which an FFT cannot evaluate and a windowed-sinc filter would only approximate near Nyquist.
    """
    if rate == 0:
        return fractional_shift(x, samples)
    n = x.size
    ext = np.concatenate([x, x[::-1]])
    m = ext.size
    spectrum = np.fft.fftshift(np.fft.fft(ext))  # bin j is frequency (j - m // 2) / m
    step, first = 1.0 + rate, samples - rate * (n - 1) / 2
    weights = spectrum * np.exp(2j * np.pi * np.arange(m) * first / m)
    times = step * np.arange(n) + first
    # sum_j weights_j w^(j t), w = exp(2 pi i step / m); the factor puts the bins at j - m // 2
    series = czt(weights, n, w=np.exp(2j * np.pi * step / m), a=1.0)
    return np.real(np.exp(-2j * np.pi * (m // 2) * times / m) * series) / m


def as_inputs(signals: Signals, names) -> Signals:
    """``signals`` with the recorded channels ``names`` moved from the outputs to the extra
    inputs (a channel moved already is left as it is)."""
    move = [name for name in names if name in signals.sensors]
    if not move:
        return signals
    keep = [k for k, name in enumerate(signals.sensors) if name not in move]
    extra = {**signals.extra, **{name: signals.y[:, signals.sensors.index(name)].copy() for name in move}}
    return replace(signals, y=signals.y[:, keep], sensors=tuple(signals.sensors[k] for k in keep), extra=extra)


def step_levels(signals: Signals, steps) -> np.ndarray:
    """The level shifts ``steps`` ((output, first sample, size), ...) as they sit on each output, (n, K)."""
    levels = np.zeros_like(signals.y)
    for name, first, size in steps:
        levels[first:, signals.sensors.index(name)] += size
    return levels


def gain_factors(signals: Signals, gains) -> np.ndarray:
    """The gain changes ``gains`` ((output, first sample, factor), ...) as they scale each output, (n, K)."""
    factors = np.ones_like(signals.y)
    for name, first, factor in gains:
        factors[first:, signals.sensors.index(name)] *= factor
    return factors


def apply_shifts(signals: Signals, shifts, drifts=()) -> Signals:
    """Signals with each named channel (an output or the input) moved by its shift and its clock's
    drift taken out (:func:`moved`)."""
    u, y = signals.u, signals.y.copy()
    shift, drift = dict(shifts), dict(drifts)
    for name in sorted(set(shift) | set(drift)):
        samples, rate = shift.get(name, 0.0), drift.get(name, 0.0)
        if name == signals.input_name:
            u = moved(u, samples, rate)
        else:
            k = signals.sensors.index(name)
            y[:, k] = moved(y[:, k], samples, rate)
    return replace(signals, u=u, y=y)


@dataclass(frozen=True)
class FittedModel:
    """A :class:`ModelSpec` fitted on ``window`` of the (shifted) signals; ``raw`` keeps
    them unshifted, for refits (shifting twice would double a delay's fix).

    ``theta`` is (q, K): disturbance coefficients per sensor, ``theta_cov`` (K, q, q).
    """

    spec: ModelSpec
    fit: ArmaxFit
    theta: np.ndarray
    theta_cov: np.ndarray
    window: tuple[int, int]
    signals: Signals = field(repr=False)
    #: The signals before the spec's shifts (what a refit must start from).
    raw: Signals = field(default=None, repr=False)
    #: Samples left out of every error (clipped outputs' rails and their guard), (n,) bool.
    excluded: np.ndarray | None = field(default=None, repr=False, compare=False)

    def disturbance(self) -> np.ndarray:
        """The fitted disturbance on every sample, (n, K)."""
        phi = disturbance_columns(self.spec, self.signals)
        return phi @ self.theta

    def one_step_errors(self) -> np.ndarray:
        """One-step prediction errors on the whole record, (n, K)."""
        s, d = self.signals, self.disturbance()
        u = s.inputs(self.spec)
        return np.column_stack([m.prediction_errors(s.y[:, k] - d[:, k], u) for k, m in enumerate(self.fit.models)])

    def simulation_errors(self) -> np.ndarray:
        """Output minus the noise-free simulated response (and the disturbance), (n, K)."""
        s, d = self.signals, self.disturbance()
        return s.y - d - self.simulated()

    def simulated(self) -> np.ndarray:
        """The noise-free response to the input, (n, K), without roots that duplicate a
        modelled disturbance (:func:`response_free_of`)."""
        s = self.signals
        return response_free_of(self.spec, self.fit, s.inputs(self.spec), s.y - self.disturbance(), slice(*self.window))


def widened_start(model: FittedModel, spec: ModelSpec) -> FittedModel | None:
    """``model`` as a start for ``spec`` when ``spec`` only adds inputs (a nonlinear term, a
    second input): the same A and C, B with zero rows for the new inputs, no model for an
    output that became an input. None when ``spec`` changes more. A fit from scratch with a
    second input needs twice the iteration cap and its half-record refits diverged (held-out
    error 0.06 -> 0.6 on the Chapter 2 system)."""
    old = model.spec
    same = replace(spec, terms=old.terms, inputs_from=old.inputs_from)
    if same != old or spec.terms[: len(old.terms)] != old.terms:
        return None
    added = len(spec.terms) - len(old.terms)
    names = model.signals.sensors
    keep = [k for k, name in enumerate(names) if name not in spec.inputs_from]
    models = []
    for i, k in enumerate(keep):
        m = model.fit.models[k]
        b = np.vstack([m.b, np.zeros((added, m.b.shape[1]))])
        models.append(replace(m, b=b, output=f"y{i + 1}"))  # fit_armax's names for arrays
    fit = replace(model.fit, models=tuple(models), covariance=tuple(model.fit.covariance[k] for k in keep))
    return replace(model, spec=spec, fit=fit)


def usable(n: int, spec: ModelSpec) -> np.ndarray:
    """Samples where every error is meaningful: away from start-up, non-causal taps and shift
    edges, (n,) bool."""
    na, nb, nc, nk = spec.orders
    drift = max((abs(r) * n / 2 for _, r in spec.drifts), default=0.0)  # the move at either end
    shift = max((abs(s) for _, s in spec.shifts), default=0.0) + drift
    head = max(na, nc + spec.extra_nc, nk + nb - 1, n // 50) + int(np.ceil(shift)) + 8
    tail = max(0, -nk) + int(np.ceil(shift)) + 8
    mask = np.zeros(n, bool)
    mask[head : n - tail] = True
    return mask


def model_bic(model, kind: str = "one_step", channels=None, mask: np.ndarray | None = None) -> float:
    """BIC of a model's in-sample one-step (or simulation) errors: ``N sum log V_k + p log(N K)``
    over ``channels`` (default all: two models compare on the outputs they share) and the
    samples ``mask`` (default :func:`usable`'s; models of different orders compare on the
    samples all can use); the baseline's order choice uses the same criterion
    (:func:`armaxmodal.estimate.orders.information_criterion`)."""
    s = model.signals
    mask = usable(s.n, model.spec) if mask is None else mask
    errors = model.one_step_errors() if kind == "one_step" else model.simulation_errors()
    e = errors[mask][:, [s.sensors.index(c) for c in (s.sensors if channels is None else channels)]]
    n, k = e.shape
    pieces = 2 if isinstance(model, PiecewiseModel) else 1
    p = pieces * model.spec.n_parameters(k) + len(model.spec.shifts) + len(model.spec.drifts)
    return float(n * np.sum(np.log(np.mean(e**2, axis=0))) + p * np.log(n * k))


def clip_masks(spec: ModelSpec, signals: Signals) -> dict[int, np.ndarray]:
    """``{column: (n,) bool}``: the rail samples of each clipped output of ``spec``."""
    columns = [signals.sensors.index(name) for name in spec.clipped]
    return {k: clipped_mask(signals.y[:, k]) for k in columns}


def counted(model) -> np.ndarray:
    """Samples whose errors count: :func:`usable` without the model's excluded ones, (n,) bool."""
    mask = usable(model.signals.n, model.spec)
    return mask if model.excluded is None else mask & ~model.excluded


#: Noise SDs from a rail within which a clipped channel's predicted response leaves a sample
#: out of every error. Near the rail only samples whose noise pulled them inside survive, so
#: their errors are biased (truncation: a clipped ride read as a quadratic spring before this
#: guard); choosing samples by the prediction, which the noise does not enter, is not.
RAIL_GUARD_SD = 3.0


def _excluded(signals: Signals, spec: ModelSpec, masks: dict, predicted: np.ndarray) -> np.ndarray:
    """The rail samples of the clipped outputs and those predicted within the guard of a rail."""
    out = np.zeros(signals.n, bool)
    for k, rail in masks.items():
        y = signals.y[:, k]
        sd = float(np.std((y - predicted[:, k])[~rail & usable(signals.n, spec)]))
        if rail[np.argmax(y)]:
            out |= predicted[:, k] > y.max() - RAIL_GUARD_SD * sd
        if rail[np.argmin(y)]:
            out |= predicted[:, k] < y.min() + RAIL_GUARD_SD * sd
        out |= rail
    return out


def fit_model(
    spec: ModelSpec, signals: Signals, window: tuple[int, int] | None = None, start: FittedModel | None = None
) -> FittedModel:
    """Fit ``spec`` on ``window`` (default: the whole record) of ``signals`` (unshifted).

    Missing samples (clipped outputs' rails, a fault's samples): fit, fill them with the
    fitted one-step prediction (in the channel's shifted frame, moved back, as the fill
    applies to the recorded signal), refit; ``IMPUTE_PASSES`` times. The model's
    :attr:`FittedModel.signals` hold the filled record, ``raw`` the recorded.
    """
    signals = as_inputs(signals, spec.inputs_from)
    rails = clip_masks(spec, signals)
    missing = {k: m.copy() for k, m in rails.items()}
    for name, samples in spec.faults:
        k = signals.sensors.index(name)
        missing.setdefault(k, np.zeros(signals.n, bool))[list(samples)] = True
    model = _fit_once(spec, signals, window, start)
    if not missing:
        return model
    for _ in range(IMPUTE_PASSES):
        model = _fit_once(spec, _filled(model, signals, missing), window, model)
    excluded = _excluded(signals, spec, rails, model.simulated() + model.disturbance())
    for m in missing.values():
        excluded |= m
    return replace(model, raw=signals, excluded=excluded)


def _filled(model: FittedModel, signals: Signals, masks: dict) -> Signals:
    """``signals`` with each channel's missing samples filled by ``model``'s one-step
    prediction (:func:`~.clipping.fill_by_prediction`) in the model's (shifted) time frame,
    then moved back to the recorded frame."""
    y = signals.y.copy()
    levels = step_levels(signals, model.spec.steps)  # the fill is made without them: put back
    factors = gain_factors(signals, model.spec.gains)
    shifts, drifts = dict(model.spec.shifts), dict(model.spec.drifts)
    s = model.signals
    u, dist = s.inputs(model.spec), model.disturbance()
    for k, gone in masks.items():
        shift, rate = shifts.get(signals.sensors[k], 0.0), drifts.get(signals.sensors[k], 0.0)
        timed = shift or rate
        missing = moved(gone.astype(float), shift, rate) > 0.5 if timed else gone
        filled = fill_by_prediction(s.y[:, k] - dist[:, k], u, model.fit.models[k], missing) + dist[:, k]
        filled = moved(filled, -shift, -rate) if timed else filled  # back, to first order in the rate
        y[gone, k] = filled[gone] * factors[gone, k] + levels[gone, k]
    return replace(signals, y=y)


def _fit_once(spec: ModelSpec, signals: Signals, window, start: FittedModel | None) -> FittedModel:
    # a level shift and a gain change are the recorded channel's: taken out before any shift moves it
    true = (signals.y - step_levels(signals, spec.steps)) / gain_factors(signals, spec.gains)
    shifted = apply_shifts(replace(signals, y=true), spec.shifts, spec.drifts)
    lo, hi = window or (0, signals.n)
    na, nb, nc, nk = spec.orders
    phi = disturbance_columns(spec, signals)
    k_count = len(signals.sensors)
    cov = np.zeros((k_count, phi.shape[1], phi.shape[1]))
    u, y = shifted.inputs(spec)[lo:hi], shifted.y[lo:hi]
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
            theta, cov = _disturbance_ls(fit, u, y, phi[lo:hi], spec, theta)
    return FittedModel(spec, fit, theta, cov, (lo, hi), shifted, signals)


#: A pole pair within this distance (Hz) of a modelled line (or a real root near 1 with a
#: modelled trend) and damped less than UNDAMPED duplicates the disturbance.
LINE_MERGE_HZ = 0.05
#: a line is a pole damped below this: the one rule of the mode selection's (LineSettings.undamped)
UNDAMPED = DEFAULTS.lines.undamped


def response_free_of(
    spec: ModelSpec, fit: ArmaxFit, u: np.ndarray, y: np.ndarray, rows: slice = slice(None)
) -> np.ndarray:
    """The response ``B'/A' u`` per sensor, (n, K): ``A'`` is the fit's A without the roots
    that duplicate a modelled disturbance (a pole pair on a line, a root at 1 with a trend) and
    ``B'`` is refitted to ``y[rows]`` (the model's fit window) by least squares for that ``A'``
    (the response is linear in B).

    PEM happily spends a spare pole pair on a line (it predicts a sinusoid perfectly), but
    that pole, driven by the broadband input, rings near the line in the simulated response
    and corrupts every estimate built on the simulation residual."""
    fs = fit.fs
    roots = np.roots(fit.models[0].a)
    f_root = np.abs(np.angle(roots)) * fs / (2 * np.pi)
    freqs = list(spec.lines_hz) + ([0.0] if spec.trend_degree >= 0 else [])
    dup = np.zeros(roots.size, bool)
    for f in freqs:
        slack = max(2 * np.pi * f / fs * UNDAMPED, 1e-3)
        dup |= (np.abs(f_root - f) < LINE_MERGE_HZ) & (np.abs(roots) > 1 - slack)
    if not dup.any():
        return np.column_stack([m.simulate(u) for m in fit.models])
    uf = lfilter([1.0], np.real(np.poly(roots[~dup])), u, axis=0).reshape(u.shape[0], -1)
    _, nb, _, nk = fit.orders
    x = np.column_stack([lagged(uf[:, m], nk + j) for m in range(uf.shape[1]) for j in range(nb)])
    return x @ np.linalg.lstsq(x[rows], y[rows], rcond=None)[0]


def lagged(x: np.ndarray, k: int) -> np.ndarray:
    """``x(t - k)`` with zeros outside the record (k may be negative)."""
    out = np.zeros_like(x)
    if k >= 0:
        out[k:] = x[: x.size - k]
    else:
        out[:k] = x[-k:]
    return out


def _disturbance_ls(fit: ArmaxFit, u, y, phi, spec, theta):
    """Disturbance coefficients given the dynamics: least squares of the simulation residual
    ``y - G u`` on the regressors, with a Newey-West covariance (the residual is coloured).

    Not GLS through the noise model: a root of A that has absorbed part of a line zeroes the
    ``A / C``-filtered regressor there, starving the estimate; ``G`` is taken without such
    roots (:func:`response_free_of`)."""
    mask = usable(u.shape[0], spec)  # u is (n, inputs) once a term enters
    q = phi.shape[1]
    x = phi[mask]
    xtx_inv = np.linalg.pinv(x.T @ x)
    cov = np.zeros((len(fit.models), q, q))
    lag = int(4 * mask.sum() ** (1 / 3))
    resid = y - response_free_of(spec, fit, u, y - phi @ theta)
    theta = xtx_inv @ (x.T @ resid[mask])
    for k in range(len(fit.models)):
        r = resid[mask, k]
        score = x * (r - x @ theta[:, k])[:, None]
        meat = score.T @ score
        for j in range(1, lag + 1):
            g = score[j:].T @ score[:-j]
            meat += (1 - j / (lag + 1)) * (g + g.T)
        cov[k] = xtx_inv @ meat @ xtx_inv
    return theta, cov


#: a fold model whose fastest mode grows by more than this over the half it simulates diverges, and
#: its simulation errors judge nothing: the real root an offset or a trend puts just outside the
#: circle grows 1.7-4.5 times (a drift on the supine ride, the Chapter 2 system, a shake-table IMU),
#: and the simulation still follows the record; Painter Street's half-record models grow 788 to
#: 5e16 times (an oscillatory pole at radius 1.0024), their held-out fits -6,655 % and worse
DIVERGENT_GROWTH = 100.0


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
    growth : float
        The factor by which a fold model's fastest-growing mode (a root of A outside the unit
        circle) grows over the half it simulates; 1 when every root is inside.
    """

    one_step: np.ndarray
    simulation: np.ndarray
    mask: np.ndarray
    growth: float = 1.0

    @property
    def simulates(self) -> bool:
        """Do the simulation errors mean something? Not where a mode grows by more than
        :data:`DIVERGENT_GROWTH` over the half simulated."""
        return self.growth <= DIVERGENT_GROWTH

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
    signals = as_inputs(signals, spec.inputs_from)
    n = signals.n
    half = n // 2
    one = np.zeros((n, len(signals.sensors)))
    sim = np.zeros_like(one)
    mask, growth = np.ones(n, bool), 1.0
    for fit_window, test in (((0, half), slice(half, n)), ((half, n), slice(0, half))):
        model = fit_model(spec, signals, fit_window, start)
        one[test] = model.one_step_errors()[test]
        sim[test] = model.simulation_errors()[test]
        mask &= counted(model)
        growth = max(growth, _growth(model, test))
    return HeldOut(one, sim, mask, growth)


def _growth(model: FittedModel, simulated: slice) -> float:
    """The factor by which the model's fastest-growing mode (A is shared by every output) grows
    over the samples ``simulated``: ``r^span`` for the largest root radius ``r`` past 1, else 1."""
    radius = float(np.max(np.abs(np.roots(model.fit.models[0].a)), initial=0.0))
    span = simulated.stop - simulated.start
    return float(np.exp(min(span * np.log(radius), 700.0))) if radius > 1.0 else 1.0


@dataclass(frozen=True)
class PiecewiseModel:
    """One spec fitted either side of a change (the ``time_varying`` fix): the same orders
    and effects, modal parameters free to move at ``change`` (a sample index)."""

    spec: ModelSpec
    before: FittedModel
    after: FittedModel
    change: int

    @property
    def signals(self) -> Signals:
        return self.before.signals

    @property
    def fit(self) -> ArmaxFit:
        return self.before.fit

    @property
    def raw(self) -> Signals:
        return self.before.raw

    @property
    def excluded(self) -> np.ndarray | None:
        parts = [m.excluded for m in (self.before, self.after) if m.excluded is not None]
        return np.logical_or.reduce(parts) if parts else None

    def _join(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        out = a.copy()
        out[self.change :] = b[self.change :]
        return out

    def disturbance(self) -> np.ndarray:
        return self._join(self.before.disturbance(), self.after.disturbance())

    def one_step_errors(self) -> np.ndarray:
        return self._join(self.before.one_step_errors(), self.after.one_step_errors())

    def simulation_errors(self) -> np.ndarray:
        return self._join(self.before.simulation_errors(), self.after.simulation_errors())

    def simulated(self) -> np.ndarray:
        return self._join(self.before.simulated(), self.after.simulated())


def fit_piecewise(
    spec: ModelSpec, signals: Signals, change: int, window: tuple[int, int] | None = None, start=None
) -> PiecewiseModel:
    """:class:`PiecewiseModel` of ``spec`` on ``window`` split at ``change``, each side
    started from ``start`` (a fit of ``spec`` to the whole record) when given."""
    lo, hi = window or (0, signals.n)
    before, after = (fit_model(spec, signals, w, start) for w in ((lo, change), (change, hi)))
    return PiecewiseModel(spec, before, after, change)


def held_out_piecewise(spec: ModelSpec, signals: Signals, change: int, start=None) -> HeldOut:
    """Blocked folds inside each regime: each half of a regime predicted by the model fitted
    on the regime's other half (a model of one regime never predicts the other)."""
    signals = as_inputs(signals, spec.inputs_from)
    n = signals.n
    one = np.zeros((n, len(signals.sensors)))
    sim = np.zeros_like(one)
    mask, growth = np.ones(n, bool), 1.0
    for lo, hi in ((0, change), (change, n)):
        mid = (lo + hi) // 2
        for fit_window, test in (((lo, mid), slice(mid, hi)), ((mid, hi), slice(lo, mid))):
            model = fit_model(spec, signals, fit_window, start)
            one[test] = model.one_step_errors()[test]
            sim[test] = model.simulation_errors()[test]
            mask &= counted(model)
            growth = max(growth, _growth(model, test))
    return HeldOut(one, sim, mask, growth)
