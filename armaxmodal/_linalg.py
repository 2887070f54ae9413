"""Dense linear algebra the fitters share that LAPACK offers no routine for (CholeskyQR2)."""

from __future__ import annotations

import numpy as np
import scipy.linalg

__all__ = [
    "CHOLESKY_QR_MAX_CONDITION",
    "ONE_PASS_MAX_CONDITION",
    "basis_factor",
    "hermitian_from_upper",
    "orthonormal_basis",
    "ridged_cholesky",
]

#: a basis is made orthonormal through its Gram matrix, twice (CholeskyQR2: Fukaya et al. 2014;
#: Yamamoto et al. 2015, a half of a Householder QR's time here), while its columns, scaled to unit
#: norm, have at most this condition number: the second pass then leaves it as orthonormal as
#: Householder's (one pass alone keeps ``condition^2 x 1e-16`` of it, and a count's split fit, two
#: poles nearly one, lost its normal equations' positive definiteness so). The method's bound is
#: about 1e8; the DFT modal bases of the benchmark chain and the bundled rides have a median of
#: 8-80 and at most 3,900. Beyond it Householder's QR keeps every digit.
CHOLESKY_QR_MAX_CONDITION = 1e6
#: ... and the second pass is left out where that condition number is at most this: one pass then
#: leaves ``Q`` orthonormal to ``100^2 x 1.1e-16 = 1.1e-12``, far inside what the modal model's normal
#: equations keep (their guard forms the rows below a ratio of 1e-6). 99 % of the count's bases on
#: the benchmark chain (median 8, at most 143); its ``select_modes`` 8 % faster, the modes the same to 1e-13
ONE_PASS_MAX_CONDITION = 1e2


def orthonormal_basis(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The economic QR factorisation of a tall matrix, by its Gram matrix where that is exact enough.

    Parameters
    ----------
    a : (m, k) float64, F-ordered, m >= k
        Full column rank; its memory is overwritten (it holds ``Q`` on return).

    Returns
    -------
    q : (m, k) ndarray
        Orthonormal columns.
    r : (k, k) ndarray
        Upper triangular, ``a = q @ r``.

    Notes
    -----
    CholeskyQR2 (``R`` from the Gram matrix of the columns scaled to unit norm, ``Q = a R^-1``,
    and the same again of ``Q``) where those columns' condition number is at most
    :data:`CHOLESKY_QR_MAX_CONDITION` (one pass where it is at most :data:`ONE_PASS_MAX_CONDITION`),
    else Householder reflections (LAPACK's ``geqrf``). They agree to rounding; the first takes half
    the time, and the QR is a third of a modal-model fit's.

    Examples
    --------
    >>> import numpy as np
    >>> from armaxmodal._linalg import orthonormal_basis
    >>> a = np.asfortranarray(np.random.default_rng(0).standard_normal((100, 4)) * [1.0, 1e3, 1e-3, 7.0])
    >>> q, r = orthonormal_basis(a.copy(order="F"))
    >>> bool(np.allclose(q.T @ q, np.eye(4))), bool(np.allclose(q @ r, a))
    (True, True)
    """
    b, r, formed = basis_factor(a)
    return (b, r) if formed else (scipy.linalg.blas.dtrsm(1.0, r, b, side=1, overwrite_b=1), r)


def basis_factor(a: np.ndarray) -> tuple[np.ndarray, np.ndarray, bool]:
    """:func:`orthonormal_basis`'s ``R``, with ``Q`` formed only where one pass of the Gram matrix
    does not suffice.

    Parameters
    ----------
    a : (m, k) float64, F-ordered, m >= k
        Full column rank; its memory may be overwritten (it holds ``Q`` where ``formed``).

    Returns
    -------
    b : (m, k) ndarray
        ``Q`` where ``formed``; else ``a`` itself, unchanged, and ``Q = a R^-1`` is left to the
        caller, who applies ``R^-1`` to its products with the basis instead (a triangular solve
        of the whole basis was a seventh of a modal-model evaluation; the products are as exact,
        since ``Q`` of one pass is ``a R^-1`` to the same rounding).
    r : (k, k) ndarray
        Upper triangular, ``a = Q @ r``.
    formed : bool
        Whether ``b`` is ``Q``.
    """
    gram = scipy.linalg.blas.dsyrk(1.0, a, trans=1)  # the upper triangle of a' a
    scale = 1.0 / np.sqrt(np.diag(gram))
    try:
        unit = scipy.linalg.cholesky(gram * np.outer(scale, scale), lower=False, check_finite=False)
        condition = np.linalg.cond(unit)
    except np.linalg.LinAlgError:  # not positive definite in floating point: Householder's
        condition = np.inf
    if not condition <= CHOLESKY_QR_MAX_CONDITION:
        return (*scipy.linalg.qr(a, mode="economic", overwrite_a=True, check_finite=False), True)
    r = unit / scale  # a D = Q U for the column scaling D, so a = Q (U D^-1)
    if condition <= ONE_PASS_MAX_CONDITION:
        return a, r, False
    q = scipy.linalg.blas.dtrsm(1.0, r, a, side=1, overwrite_b=1)
    # the second pass: Q is orthonormal to condition^2 x 1e-16, so its Gram matrix is I to that
    again = scipy.linalg.cholesky(scipy.linalg.blas.dsyrk(1.0, q, trans=1), lower=False, check_finite=False)
    return scipy.linalg.blas.dtrsm(1.0, again, q, side=1, overwrite_b=1), again @ r, True


def hermitian_from_upper(upper: np.ndarray) -> np.ndarray:
    """The Hermitian matrix whose upper triangle BLAS's ``herk`` filled (its lower one zero)."""
    return upper + np.conj(np.triu(upper, 1)).T


def ridged_cholesky(gram: np.ndarray) -> np.ndarray:
    """The upper Cholesky factor of ``gram`` plus a ridge of 1e-12 of its mean diagonal, so that a
    null direction stays solvable."""
    ridge = 1e-12 * np.trace(gram) / gram.shape[0]
    return scipy.linalg.cholesky(gram + ridge * np.eye(gram.shape[0]), lower=False, check_finite=False)
