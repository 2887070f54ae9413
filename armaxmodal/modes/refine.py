"""Frequency-domain refinement of selected modes under the data's inter-sample behaviour.

A discrete ARMAX model is the exact model class only when the input is held between
samples (zero-order hold). Measured signals pass anti-aliasing filters and are band-limited;
their discrete transfer function equals the continuous one below Nyquist, which no low-order
rational function of ``z`` matches, so the PEM poles carry a model-class bias that depends on
where the input has power (measured: a 0.5-20 Hz sweep puts the 16.2 Hz mode 2.9 % low and
mode 3's damping 12 % high). Following Pintelon & Schoukens (System Identification: a
Frequency Domain Approach, 2nd ed., Ch. 6-7), the DFT of every sensor is fitted over the
excited band as ``Y = G(Omega) U + T(z)``: ``G`` the modal sum with continuous poles, in
``s = i w`` for a band-limited input or in ``z`` for a held one, and ``T`` the transient
(leakage) term, a rational function of ``z`` with the same poles. Residues, direct terms and
transient coefficients enter linearly and are projected out (variable projection), so only
the frequencies and damping ratios are iterated, from the ARMAX selection. Both hold
assumptions are fitted and the one with the lower residual (the same number of parameters)
is reported: the data choose it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.optimize

from armaxmodal._kernels import modal_basis, modal_moved
from armaxmodal._threads import single_blas_thread
from armaxmodal.exceptions import OrderError
from armaxmodal.modes.settings import DEFAULTS, NORMAL_EQUATIONS_MIN_RATIO, DftSettings
from armaxmodal.recording import Recording

HOLDS = ("bandlimited", "zoh")


@dataclass(frozen=True)
class ModalRefinement:
    """Modes refitted to the recording's DFT.

    Attributes
    ----------
    hold : str
        Inter-sample assumption of the reported fit ("bandlimited" or "zoh").
    freq_hz, damping, freq_sd, damping_sd : (n_modes,) ndarray
        Undamped natural frequencies (Hz), damping ratios and their standard deviations.
    shapes : (n_sensors, n_modes) complex ndarray
        EPFRF modal constants (Eq. 3.24), ``-r / lambda^2`` from the continuous residues.
    cost : dict
        Weighted residual sum of squares of each hold's fit after the same few steps from
        the same start (same lines, same parameters): the basis of the choice.
    band_hz : (float, float)
        The fitted band.
    """

    hold: str
    freq_hz: np.ndarray
    damping: np.ndarray
    freq_sd: np.ndarray
    damping_sd: np.ndarray
    shapes: np.ndarray
    cost: dict
    band_hz: tuple[float, float]


def _poles(x: np.ndarray) -> np.ndarray:
    wn, xi = np.exp(x[0::2]), x[1::2]
    return -xi * wn + 1j * wn * np.sqrt(1.0 - xi**2)


def _pole_derivatives(x: np.ndarray) -> np.ndarray:
    """``d lambda / d x``: (n_modes, 2) for x = (log wn, xi) per mode."""
    wn, xi = np.exp(x[0::2]), x[1::2]
    return np.column_stack([_poles(x), -wn - 1j * wn * xi / np.sqrt(1.0 - xi**2)])


def _pair(h: np.ndarray, h_conj: np.ndarray) -> np.ndarray:
    """Real-coefficient columns a, b such that ``(a + i b)`` times ``h`` plus its conjugate
    partner is ``alpha a + beta b`` for a complex coefficient ``alpha + i beta``; (L, 2)."""
    return np.column_stack([h + h_conj, 1j * (h - h_conj)])


class _Compressed:
    """A separable model's residual and Jacobian rotated onto ``n + 1`` rows: the QR factor
    ``R`` of ``[J r]`` at each point. ``J_c' J_c = J' J``, ``J_c' r_c = J' r`` and
    ``|r_c| = |r|``, so a trust-region solver takes the same steps, while it holds
    (n + 1) x n numbers instead of one row per DFT line, sensor and real or imaginary part
    (scipy keeps about seven copies of the Jacobian: 0.5 GB for a one-hour ride). The factor
    is built one sensor's rows at a time (the order of rows does not change it). Each
    residual costs a Jacobian too, so ``r_c`` and ``J_c`` always come from one factor."""

    def __init__(self, model: _SeparableModel):
        self.model = model
        self._x = None

    def _factor(self, x):
        if self._x is None or not np.array_equal(x, self._x):
            factor = np.zeros((0, x.size + 1))
            for jac, resid in self.model.sensor_rows(x):
                rows = np.vstack([factor, np.column_stack([jac, resid])])
                factor = scipy.linalg.qr(rows, mode="raw", overwrite_a=True, check_finite=False)[1]
            self._x, self._r = x.copy(), factor
        return self._r

    def residual(self, x):
        return self._factor(x)[:, -1]

    def jacobian(self, x):
        return self._factor(x)[:, :-1]


class _SeparableModel:
    """``Y = Phi(x) coef`` over DFT lines, with ``coef`` (residues, direct and transient terms)
    projected out: residual and Golub-Pereyra Jacobian in the frequencies and dampings only.

    Columns of ``Phi``: a plant pair per mode (``1 / (s - lambda)`` times U, or its held form
    in ``z``), the direct term U, a transient pair per mode (``1 / (1 - mu z^-1)``), a constant.
    Rows are the real parts of the lines stacked over the imaginary parts; the sensors are
    right-hand sides sharing one basis.
    """

    def __init__(self, s, z_inv, u, y_weighted, dt, hold):
        self.s, self.z_inv, self.u, self.dt, self.hold = s, z_inv, u, dt, hold
        self.b = np.vstack([y_weighted.real, y_weighted.imag])
        self._x = None

    def release(self) -> None:
        """Let go of the factors of the last point (the size of the data)."""
        self._x = self.q = self.resid = self.slopes = None

    def _solve(self, x):
        if self._x is not None and np.array_equal(x, self._x):
            return
        lam = _poles(x)
        # the real parts of the lines over their imaginary parts, filled in place by a kernel
        # (a one-hour ride has 10^5 lines or more: no complex copy of the basis, no copy for the
        # QR, and the last point's factors are let go first)
        self.release()
        lines = self.s.size
        a = np.empty((2 * lines, 4 * lam.size + 2), order="F")
        slopes = np.empty((4, lam.size, lines), complex)
        modal_basis(self.s, self.z_inv, self.u, lam, self.dt, self.hold == "bandlimited", a, slopes)
        q, r = scipy.linalg.qr(a, mode="economic", overwrite_a=True, check_finite=False)
        qtb = q.T @ self.b
        self._x, self.lam, self.q, self.r, self.slopes = x.copy(), lam, q, r, slopes
        self.coef = scipy.linalg.solve_triangular(r, qtb, check_finite=False)
        self.resid = self.b - q @ qtb

    def residual(self, x):
        self._solve(x)
        return self.resid.ravel()

    def sensor_rows(self, x):
        """Per sensor, its rows of the Jacobian and of the residual, ``(2 L, n)`` and ``(2 L,)``."""
        self._solve(x)
        for k in range(self.b.shape[1]):
            yield self.jacobian(x, sensors=[k]), self.resid[:, k]

    def jacobian(self, x, sensors=None):
        """``d resid / d x`` = ``-P_perp dA coef - A^+' dA' resid`` (Golub & Pereyra, 1973):
        the rows of ``sensors`` (a list of indices; default all). ``dA coef`` comes from a kernel
        (the per-mode products in numpy took 20 ms of 25 for 8,000 lines and 5 sensors)."""
        self._solve(x)
        n, lines = self.lam.size, self.s.size
        d_lam = _pole_derivatives(x)
        sensors = slice(None) if sensors is None else sensors
        coef, resid = self.coef[:, sensors], self.resid[:, sensors]
        width = resid.shape[1]
        alpha = coef[0 : 2 * n : 2] + 1j * coef[1 : 2 * n : 2]
        beta = coef[2 * n + 1 : 4 * n + 1 : 2] + 1j * coef[2 * n + 2 : 4 * n + 2 : 2]
        moved = np.empty((2 * lines, width, x.size))
        modal_moved(self.slopes, alpha, beta, d_lam, moved)
        seen = np.conj(self.slopes.reshape(4 * n, lines)) @ (resid[:lines] + 1j * resid[lines:])
        back = _basis_slopes_times(seen, d_lam, coef.shape[0])
        moved = moved.reshape(2 * lines, -1)
        # every column at once: two passes over Q
        moved -= self.q @ (self.q.T @ moved + scipy.linalg.solve_triangular(
            self.r, back.reshape(coef.shape[0], -1), trans="T", check_finite=False))  # fmt: skip
        return moved.reshape(resid.size, x.size)

    def normal_equations(self, x):
        """``(J' J, J' r, |r|^2)`` over every sensor's rows without forming ``J``: from the Gram
        matrix of the pole slopes and their projections on the basis (``J = P_perp M - Q E``
        with ``M = -dA coef`` and ``E = R^-T dA' r``, whose two parts are orthogonal, and
        ``P_perp r = r``). Its cost does not grow with the sensors; 6 ms against 17 for the
        Jacobian's products (8,000 lines, 5 sensors, 4 modes), the same to 1e-14."""
        self._solve(x)
        n, lines, width = self.lam.size, self.s.size, self.b.shape[1]
        d_lam, coef = _pole_derivatives(x), self.coef
        alpha = coef[0 : 2 * n : 2] + 1j * coef[1 : 2 * n : 2]
        beta = coef[2 * n + 1 : 4 * n + 1 : 2] + 1j * coef[2 * n + 2 : 4 * n + 2 : 2]
        # M_si = sum_c slopes_c w[c, s, i]: each slope's weight in -dA/dx_i coef_s (a pole's
        # slopes enter its own two parameters only)
        w = np.zeros((4, n, width, n, 2), complex)
        g, own = d_lam[:, None, :], np.arange(n)
        for slope, coefficient in enumerate((alpha, np.conj(alpha), beta, np.conj(beta))):
            turn = np.conj(g) if slope % 2 else g  # the conjugate pole's slopes move with conj(d lambda)
            w[slope, own, :, own, :] = -turn * coefficient[:, :, None]
        w = w.reshape(4 * n, width, 2 * n)
        slopes = self.slopes.reshape(4 * n, lines)
        slopes_h = np.conj(slopes)
        seen = slopes_h @ (self.resid[:lines] + 1j * self.resid[lines:])
        # Q' M = Re(Q_c^H slopes w), Q_c = Q's real rows + i its imaginary rows
        on_basis = (np.conj(slopes_h @ (self.q[:lines] + 1j * self.q[lines:])).T @ w.reshape(4 * n, -1)).real
        on_basis = on_basis.reshape(-1, width, 2 * n)
        e = scipy.linalg.solve_triangular(self.r, _basis_slopes_times(seen, d_lam, coef.shape[0]).reshape(
            coef.shape[0], -1), trans="T", check_finite=False).reshape(-1, width, 2 * n)  # fmt: skip
        slopes_gram = slopes_h @ slopes.T
        m_m = np.einsum("csi,csk->ik", np.conj(w), (slopes_gram @ w.reshape(4 * n, -1)).reshape(w.shape)).real
        off_basis = m_m - np.einsum("asi,ask->ik", on_basis, on_basis)
        power = float(np.sum(self.resid**2))
        if np.min(np.diag(off_basis) / np.diag(m_m)) < NORMAL_EQUATIONS_MIN_RATIO:
            # a pole's slope almost in the basis (a pole far outside the band, two poles nearly
            # one): the difference of squares has lost too many digits, so the rows are formed
            gram, grad = 0.0, 0.0
            for jac, resid in self.sensor_rows(x):
                gram, grad = gram + jac.T @ jac, grad + jac.T @ resid
            return gram, grad, power
        gram = off_basis + np.einsum("asi,ask->ik", e, e)
        return gram, np.einsum("csi,cs->i", np.conj(w), seen).real, power


def _basis_slopes_times(seen: np.ndarray, d_lam: np.ndarray, n_coef: int) -> np.ndarray:
    """``dA/dx_i' r_s``, (n_coef, S, 2 n), from ``seen`` = each pole's four slopes' conjugates
    times the complex residual, (4 n, S): a pole's plant and transient pairs move with it."""
    n, width = d_lam.shape[0], seen.shape[1]
    seen, g = seen.reshape(4, n, 1, width), d_lam[:, :, None]
    back = np.zeros((n_coef, width, 2 * n))
    params, rows = np.arange(2 * n), np.repeat(np.arange(n), 2)
    for first, (own, partner) in ((2 * rows, seen[:2]), (2 * n + 1 + 2 * rows, seen[2:])):
        u, v = (np.conj(g) * own).reshape(2 * n, width), (g * partner).reshape(2 * n, width)
        back[first, :, params], back[first + 1, :, params] = (u + v).real, (u - v).imag
    return back


def _sandwich_sd(blocks, n_par: int) -> np.ndarray:
    """Standard errors of the nonlinear parameters from the variable-projection Jacobian,
    heteroscedasticity-consistent (White's HC1 sandwich). The residual's variance is not
    the same on every DFT line: input noise and the model-class gap grow with |H| near the
    resonances, so one pooled variance understated the spread of the refit's first mode
    2-3 times on band-limited rides (scripts/mc_coverage.py: 78 % coverage). ``blocks``
    yields ``(jacobian rows, residual rows)``: the sums are taken a block at a time."""
    gram, meat, rows = 0.0, 0.0, 0
    for jac, resid in blocks:
        gram, meat, rows = gram + jac.T @ jac, meat + (jac * resid[:, None] ** 2).T @ jac, rows + resid.size
    bread = np.linalg.pinv(gram)
    scale = rows / max(rows - n_par, 1)
    return np.sqrt(np.clip(np.diag(bread @ meat @ bread) * scale, 0, None))


@single_blas_thread
def refine_modes(
    recording: Recording,
    freq_hz,
    damping,
    *,
    band_hz: tuple[float, float],
    hold: str = "auto",
    max_nfev: int = 60,
    settings: DftSettings = DEFAULTS.dft,
) -> ModalRefinement:
    """Refit the frequencies, damping ratios and shapes of selected modes to the DFT of a
    recording (see the module notes).

    Parameters
    ----------
    recording : Recording
    freq_hz, damping : (n_modes,) array_like
        Starting modes (Hz, ratio), e.g. from :func:`armaxmodal.select_modes`.
    band_hz : (lo, hi)
        Band where the input has power (Hz); only these DFT lines are fitted.
    hold : {"auto", "bandlimited", "zoh"}
        Inter-sample assumption; "auto" fits both and keeps the lower residual.
    max_nfev : int
        Cap on residual evaluations per fit.
    settings : DftSettings
        The damping bounds of a free pole.

    Returns
    -------
    ModalRefinement
    """
    return _refine_modes(recording, freq_hz, damping, band_hz=band_hz, hold=hold, max_nfev=max_nfev, settings=settings)


def _refine_modes(
    recording: Recording,
    freq_hz,
    damping,
    *,
    band_hz: tuple[float, float],
    hold: str = "auto",
    max_nfev: int = 60,
    settings: DftSettings = DEFAULTS.dft,
) -> ModalRefinement:
    """:func:`refine_modes` itself, under the caller's BLAS threads (the public function holds one)."""
    if hold not in ("auto", *HOLDS):
        raise ValueError(f"hold: expected 'auto', 'bandlimited' or 'zoh', got {hold!r}.")
    f0, x0 = np.asarray(freq_hz, dtype=float), np.asarray(damping, dtype=float)
    dt = 1.0 / recording.fs
    freq = np.fft.rfftfreq(recording.n_samples, dt)
    lines = (freq >= band_hz[0]) & (freq <= band_hz[1]) & (freq > 0)
    u = np.fft.rfft(recording.base)[lines]
    y = np.fft.rfft(recording.response, axis=0)[lines]
    n_columns = 4 * f0.size + 2  # plant and transient pairs, direct and constant terms
    if 2 * lines.sum() < 3 * n_columns:
        raise OrderError(
            f"{lines.sum()} DFT lines in {band_hz[0]:g}-{band_hz[1]:g} Hz cannot refit {f0.size} modes; "
            "record longer or widen the band."
        )
    w = 2 * np.pi * freq[lines]
    s, z_inv = 1j * w, np.exp(-1j * w * dt)
    start = np.ravel(np.column_stack([np.log(2 * np.pi * f0), x0]))
    lo = np.ravel(np.column_stack([np.full(f0.size, np.log(w[0])), np.full(f0.size, settings.min_damping)]))
    top = np.log(np.pi * recording.fs)
    hi = np.ravel(np.column_stack([np.full(f0.size, top), np.full(f0.size, settings.max_damping)]))
    start = np.clip(start, lo, hi)

    def model(hold_, weights):
        return _SeparableModel(s, z_inv, u, y * weights, dt, hold_)

    # each sensor weighted by its own noise level, estimated at the start
    start_model = model("zoh", np.ones(y.shape[1]))
    start_model.residual(start)
    sd = np.sqrt(np.mean(start_model.resid**2, axis=0))
    del start_model  # its basis and factors are the size of the data
    weights = 1.0 / np.where(sd > 0, sd, 1.0)
    models = {h: model(h, weights) for h in HOLDS}

    def fit(hold_, x, n_eval):
        m = _Compressed(models[hold_])
        result = scipy.optimize.least_squares(
            m.residual, x, jac=m.jacobian, bounds=(lo, hi), x_scale="jac", max_nfev=n_eval
        )
        models[hold_].release()  # one assumption's factors in memory at a time
        return result

    # a few steps of each assumption tell them apart (the wrong one stays well above); the
    # chosen one is then iterated to convergence
    fits = {h: fit(h, start, 4 if hold == "auto" else max_nfev) for h in (HOLDS if hold == "auto" else (hold,))}
    best = min(fits, key=lambda h: fits[h].cost)
    res = fits[best] if hold != "auto" else fit(best, fits[best].x, max_nfev)
    lam = _poles(res.x)
    models[best].residual(res.x)  # the factors at the solution (released after the fit)
    coef = models[best].coef
    n_par = coef.shape[0] * coef.shape[1] + res.x.size
    sd_par = _sandwich_sd(models[best].sensor_rows(res.x), n_par)
    r = (coef[0 : 2 * f0.size : 2] + 1j * coef[1 : 2 * f0.size : 2]).T / weights[:, None]
    if best == "zoh":  # R / (1 - mu z^-1) = R + R mu z^-1 / (1 - mu z^-1); zoh of r / (s - lambda)
        mu = np.exp(lam * dt)  # is r (mu - 1) / lambda z^-1 / (1 - mu z^-1), so r = R mu lambda / (mu - 1)
        r = r * mu * lam / (mu - 1.0)
    shapes = -r / lam**2
    f = np.abs(lam) / (2 * np.pi)
    return ModalRefinement(
        hold=best,
        freq_hz=f,
        damping=-lam.real / np.abs(lam),
        freq_sd=f * sd_par[0::2],
        damping_sd=sd_par[1::2],
        shapes=shapes,
        cost={h: float(2 * f.cost) for h, f in fits.items()},
        band_hz=(float(band_hz[0]), float(band_hz[1])),
    )
