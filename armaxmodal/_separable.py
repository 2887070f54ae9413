"""The separable least-squares problem of a modal model on DFT lines: the numerical core of
:mod:`armaxmodal.estimate.dft_model`'s fitter, kept beside ``_kernels`` and ``_linalg`` as they are
(private numerics behind a validated wrapper: no selection rule and no threshold of the stages).

The modal sum with continuous poles (``1 / (s - lambda)`` for a band-limited input, its held
form in ``z`` for a zero-order hold) and the transient (leakage) term ``T(z)`` with the same
poles are linear in the residues, the direct and the transient coefficients. Those are
projected out (variable projection, Golub & Pereyra 1973), so only each pole's
``(ln omega_n, xi)`` is iterated: the residual, its Jacobian, and its normal equations formed
without the Jacobian's rows.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from armaxmodal._kernels import modal_basis, modal_moved
from armaxmodal._linalg import basis_factor, hermitian_from_upper, ridged_cholesky

#: the normal equations take ``|P_perp M|^2`` as ``|M|^2 - |Q'M|^2``, which keeps about
#: 16 + log10 of this ratio of the two digits; below it the Jacobian's rows are formed (a light
#: pole at the Nyquist frequency kept none). A guard of the arithmetic, as ``_linalg``'s are.
NORMAL_EQUATIONS_MIN_RATIO = 1e-6


def poles(x: np.ndarray) -> np.ndarray:
    wn, xi = np.exp(x[0::2]), x[1::2]
    return -xi * wn + 1j * wn * np.sqrt(1.0 - xi**2)


def start_vector(freq_hz, damping) -> np.ndarray:
    """The parameters ``x`` (``ln omega_n, xi`` per mode) of modes in Hz and damping ratios."""
    return np.ravel(np.column_stack([np.log(2 * np.pi * np.asarray(freq_hz, float)), np.asarray(damping, float)]))


def x_bounds(lowest_w: float, dt: float, n_modes: int, min_damping: float, max_damping: float):
    """Each pole's ``(ln omega_n, xi)`` limits, ``(lo, hi)``: from half the lowest line
    (``lowest_w``, rad/s) to Nyquist, and the damping range."""
    lo = np.tile([np.log(0.5 * max(lowest_w, 1e-6)), min_damping], n_modes)
    return lo, np.tile([np.log(np.pi / dt), max_damping], n_modes)


def pole_derivatives(x: np.ndarray) -> np.ndarray:
    """``d lambda / d x``: (n_modes, 2) for x = (log wn, xi) per mode."""
    wn, xi = np.exp(x[0::2]), x[1::2]
    return np.column_stack([poles(x), -wn - 1j * wn * xi / np.sqrt(1.0 - xi**2)])


class SeparableModel:
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
        self._x = self.basis = self.slopes = self._basis_conj = None
        self.formed = True  # whether ``basis`` is Q (set by each point's factorisation)

    def release(self) -> None:
        """Let go of the factors of the last point (the size of the data)."""
        self._x = self.basis = self.resid = self.slopes = self._basis_conj = None

    def _solve(self, x):
        if self._x is not None and np.array_equal(x, self._x):
            return
        lam = poles(x)
        # the real parts of the lines over their imaginary parts, filled in place by a kernel
        # (a one-hour ride has 10^5 lines or more: no complex copy of the basis, no copy for the
        # QR); the last point's arrays are filled again where they fit
        a, slopes = self._buffers(lam.size)
        modal_basis(self.s, self.z_inv, self.u, lam, self.dt, self.hold == "bandlimited", a, slopes)
        # the basis itself where one pass of its Gram matrix gives R (Q = basis R^-1, applied to
        # the products below), else Q (basis_factor)
        basis, r, self.formed = basis_factor(a)
        self._x, self.lam, self.basis, self.r, self.slopes = x.copy(), lam, basis, r, slopes
        qtb = self.q_t(self.b)
        self.coef = scipy.linalg.solve_triangular(r, qtb, check_finite=False)
        self.resid = self.b - basis @ (qtb if self.formed else self.coef)

    def q_t(self, m: np.ndarray) -> np.ndarray:
        """``Q' m`` for a matrix ``m`` of the basis's rows."""
        product = self.basis.T @ m
        return product if self.formed else self._r_inv_t(product)

    def q_times(self, z: np.ndarray) -> np.ndarray:
        """``Q z`` for a matrix ``z`` of the basis's columns."""
        return self.basis @ (z if self.formed else scipy.linalg.solve_triangular(self.r, z, check_finite=False))

    def _r_inv_t(self, m: np.ndarray) -> np.ndarray:
        return scipy.linalg.solve_triangular(self.r, m, trans="T", check_finite=False)

    def _buffers(self, n_modes: int) -> tuple[np.ndarray, np.ndarray]:
        """The basis and slope arrays of a point with ``n_modes`` poles: the last point's where they
        have that size (``Q`` takes the basis's memory), else new ones. A fit's points all have one
        size, and fresh arrays of that size cost as much as the point's products: the allocator
        hands megabytes back to the system when they are freed, and takes them again zeroed."""
        shape, lines = (2 * self.s.size, 4 * n_modes + 2), self.s.size
        a, slopes = self.basis, self.slopes
        self.release()
        if a is None or a.shape != shape or not a.flags.f_contiguous or not a.flags.writeable:
            a, slopes = np.empty(shape, order="F"), np.empty((4, n_modes, lines), complex)
        return a, slopes

    def _conj_basis(self) -> np.ndarray:
        """The conjugate of the current basis as complex lines, ``(L, 4 n + 2)``, in an array kept from
        point to point: its real rows minus i its imaginary rows."""
        lines, width = self.s.size, self.basis.shape[1]
        if self._basis_conj is None or self._basis_conj.shape != (lines, width):
            self._basis_conj = np.empty((lines, width), complex)
        self._basis_conj.real[...] = self.basis[:lines]
        np.negative(self.basis[lines:], out=self._basis_conj.imag)
        return self._basis_conj

    def residual(self, x):
        self._solve(x)
        return self.resid.ravel()

    def residual_rms(self, x) -> np.ndarray:
        """Each sensor's residual RMS per real number at ``x`` (1 where it is 0)."""
        self._solve(x)
        level = np.sqrt(np.mean(self.resid**2, axis=0))
        return np.where(level > 0, level, 1.0)

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
        d_lam = pole_derivatives(x)
        sensors = slice(None) if sensors is None else sensors
        coef, resid = self.coef[:, sensors], self.resid[:, sensors]
        width = resid.shape[1]
        alpha = coef[0 : 2 * n : 2] + 1j * coef[1 : 2 * n : 2]
        beta = coef[2 * n + 1 : 4 * n + 1 : 2] + 1j * coef[2 * n + 2 : 4 * n + 2 : 2]
        moved = np.empty((2 * lines, width, x.size))
        modal_moved(self.slopes, alpha, beta, d_lam, moved)
        seen = np.conj(self.slopes.reshape(4 * n, lines) @ (resid[:lines] - 1j * resid[lines:]))  # conj(S) r
        back = _basis_slopes_times(seen, d_lam, coef.shape[0])
        moved = moved.reshape(2 * lines, -1)
        # every column at once: two passes over Q
        moved -= self.q_times(self.q_t(moved) + self._r_inv_t(back.reshape(coef.shape[0], -1)))
        return moved.reshape(resid.size, x.size)

    def normal_equations(self, x, rows: bool = False):
        """``(J' J, J' r, |r|^2)`` over every sensor's rows without forming ``J``: from the Gram
        matrix of the pole slopes and their projections on the basis (``J = P_perp M - Q E``
        with ``M = -dA coef`` and ``E = R^-T dA' r``, whose two parts are orthogonal, and
        ``P_perp r = r``). Its cost does not grow with the sensors; 6 ms against 17 for the
        Jacobian's products (8,000 lines, 5 sensors, 4 modes), the same to 1e-14."""
        self._solve(x)
        n, lines, width = self.lam.size, self.s.size, self.b.shape[1]
        d_lam, coef = pole_derivatives(x), self.coef
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
        # no conjugate copy of the slopes S, nor a new complex copy of Q: each is as large as the basis
        slopes = self.slopes.reshape(4 * n, lines)
        seen = np.conj(slopes @ (self.resid[:lines] - 1j * self.resid[lines:]))  # conj(S) r
        # Q' M = Re(Q_c^H slopes w) = Re((S conj(Q_c))' w), Q_c = Q's real rows + i its imaginary rows;
        # S conj(Q_c) = (S conj(basis_c)) R^-1 where Q is not formed
        seen_basis = slopes @ self._conj_basis()
        seen_basis = seen_basis.T if self.formed else self._r_inv_t(seen_basis.T)
        on_basis = (seen_basis @ w.reshape(4 * n, -1)).real
        on_basis = on_basis.reshape(-1, width, 2 * n)
        e = scipy.linalg.solve_triangular(
            self.r,
            _basis_slopes_times(seen, d_lam, coef.shape[0]).reshape(coef.shape[0], -1),
            trans="T",
            check_finite=False,
        ).reshape(-1, width, 2 * n)
        # conj(S) S', from the upper half BLAS fills
        slopes_gram = hermitian_from_upper(scipy.linalg.blas.zherk(1.0, slopes.T, trans=2))
        m_m = np.einsum("csi,csk->ik", np.conj(w), (slopes_gram @ w.reshape(4 * n, -1)).reshape(w.shape)).real
        off_basis = m_m - np.einsum("asi,ask->ik", on_basis, on_basis)
        power = float(np.sum(self.resid**2))
        if rows or np.min(np.diag(off_basis) / np.diag(m_m)) < NORMAL_EQUATIONS_MIN_RATIO:
            # a pole's slope almost in the basis (a pole far outside the band, two poles nearly
            # one): the difference of squares has lost too many digits, so the rows are formed
            # (``rows``: the caller found them lost)
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


class GramCompressed:
    """The projected residual and Jacobian reduced to ``n + 1`` rows through the normal
    equations: ``[R; 0]`` and ``[R^-T J'r; sqrt(|r|^2 - |R^-T J'r|^2)]`` with ``R'R = J'J``
    have the same ``J'J``, ``J'r`` and ``|r|`` as the full rows, so a trust-region solver
    takes the same steps. The normal equations come without the Jacobian's rows
    (:meth:`SeparableModel.normal_equations`): the nested tests run
    dozens of fits, and their Jacobians are well conditioned in ``(ln omega, xi)``."""

    def __init__(self, model: SeparableModel):
        self.model = model
        self._x = None

    def _factor(self, x):
        if self._x is None or not np.array_equal(x, self._x):
            gram, grad, power = self.model.normal_equations(x)
            try:
                r = ridged_cholesky(gram)
            except np.linalg.LinAlgError:  # the difference of squares lost J'J's definiteness where two
                gram, grad, power = self.model.normal_equations(x, rows=True)  # poles are nearly one
                r = ridged_cholesky(gram)
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
