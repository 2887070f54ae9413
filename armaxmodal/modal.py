"""Poles to natural frequency and damping ratio (thesis Section 3.3.2, Eqs. 3.15-3.16).

A discrete-time pole ``mu`` of an ARMAX model sampled every ``dt`` seconds maps to the
continuous-time pole ``lambda = ln(mu) / dt``; the undamped natural frequency is
``|lambda| / (2 pi)`` Hz and the damping ratio ``-Re(lambda) / |lambda|``. Eqs. (3.15)-(3.16)
write the same numbers with ``ln(mu mu*)`` and ``arccos``; both forms are provided so the
tests can show they agree.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "continuous_modal_parameters",
    "discrete_to_continuous",
    "discrete_modal_parameters",
    "thesis_frequency_damping",
    "pole_uncertainty",
    "mode_record",
    "modal_frf",
    "normalised_shape",
    "mac",
    "nearest_pole",
    "matched_poles",
    "new_poles",
]


def continuous_modal_parameters(lam) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Undamped frequency, damping ratio and damped frequency of continuous poles.

    Parameters
    ----------
    lam : array_like of complex
        Continuous-time poles in rad/s.

    Returns
    -------
    freq_hz, damping, damped_freq_hz : ndarray
        ``|lam| / 2pi`` (Hz), ``-Re(lam) / |lam|`` (ratio), ``|Im(lam)| / 2pi`` (Hz).
    """
    lam = np.asarray(lam, dtype=np.complex128)
    mag = np.abs(lam)
    with np.errstate(invalid="ignore", divide="ignore"):
        damping = np.where(mag > 0, -lam.real / np.where(mag > 0, mag, 1.0), np.nan)
    return mag / (2 * np.pi), damping, np.abs(lam.imag) / (2 * np.pi)


def discrete_to_continuous(mu, fs: float) -> np.ndarray:
    """Continuous poles ``lambda = ln(mu) * fs`` (rad/s) of discrete poles ``mu``."""
    return np.log(np.asarray(mu, dtype=np.complex128)) * float(fs)


def discrete_modal_parameters(mu, fs: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Undamped frequency (Hz), damping ratio and damped frequency (Hz) of discrete poles."""
    return continuous_modal_parameters(discrete_to_continuous(mu, fs))


def thesis_frequency_damping(mu, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Eqs. (3.15)-(3.16) of the thesis, written as printed.

    Parameters
    ----------
    mu : array_like of complex
        Discrete-time poles (roots of A(z)).
    dt : float
        Sampling interval in seconds.

    Returns
    -------
    freq_hz, damping : ndarray
    """
    mu = np.asarray(mu, dtype=np.complex128)
    mm = (mu * np.conj(mu)).real
    log_mm = np.log(mm)
    cos_arg = np.clip(((mu + np.conj(mu)).real) / (2 * np.sqrt(mm)), -1.0, 1.0)
    angle = np.arccos(cos_arg)
    freq = np.sqrt((log_mm / 2) ** 2 + angle**2) / (2 * np.pi * dt)
    damping = np.sqrt(log_mm**2 / (log_mm**2 + 4 * angle**2))
    return freq, damping


def pole_uncertainty(a, mu, cov_a, fs: float) -> tuple[np.ndarray, np.ndarray]:
    """Standard deviations of frequency (Hz) and damping of poles ``mu`` of ``A(z)``.

    Delta method: a root of ``z^na + a_1 z^(na-1) + ... + a_na`` moves by
    ``dmu/da_i = -mu^(na-i) / A'(mu)``; then ``lambda = fs ln(mu)``, ``f = |lambda|/2pi`` and
    ``xi = -Re(lambda)/|lambda|``.

    Parameters
    ----------
    a : (na + 1,) monic A coefficients
    mu : (k,) complex poles of A
    cov_a : (na, na) covariance of ``a_1..a_na``
    fs : sampling rate, Hz

    Returns
    -------
    sd_freq_hz, sd_damping : (k,) ndarray
    """
    a = np.asarray(a, dtype=float)
    mu = np.atleast_1d(np.asarray(mu, dtype=complex))
    na = a.size - 1
    deriv = np.polyval(np.polyder(a), mu)
    powers = mu[:, None] ** (na - np.arange(1, na + 1))[None, :]
    dmu = -powers / deriv[:, None]  # (k, na) complex
    lam = np.log(mu) * fs
    dlam = dmu * (fs / mu)[:, None]
    mag = np.abs(lam)
    lr, li = lam.real, lam.imag
    df = (lr[:, None] * dlam.real + li[:, None] * dlam.imag) / (2 * np.pi * mag[:, None])
    dxi = (-(li**2)[:, None] * dlam.real + (lr * li)[:, None] * dlam.imag) / (mag**3)[:, None]
    var_f = np.einsum("ki,ij,kj->k", df, cov_a, df)
    var_xi = np.einsum("ki,ij,kj->k", dxi, cov_a, dxi)
    return np.sqrt(np.maximum(var_f, 0)), np.sqrt(np.maximum(var_xi, 0))


def normalised_shape(shape: np.ndarray) -> np.ndarray:
    """A mode shape scaled so that its largest component is 1 (on the positive real axis).

    Parameters
    ----------
    shape : (n_sensors,) complex array_like

    Returns
    -------
    (n_sensors,) complex ndarray
        Unchanged when every component is zero.
    """
    shape = np.asarray(shape, dtype=complex).copy()
    i_big = int(np.argmax(np.abs(shape)))
    big = shape[i_big]
    if abs(big) > 0:
        shape = shape / big
        shape[i_big] = 1.0  # complex z / z can round to 0.9999999999999999 or a phase of 1e-15 deg
    return shape


def mode_record(row, shape: np.ndarray, sensors, supplemented=None) -> dict:
    """One mode of the JSON contract: frequency, damping, 95 % intervals and the shape
    (normalised to a unit largest component on the positive real axis) per sensor."""
    shape = normalised_shape(shape)
    flags = np.zeros(len(sensors), dtype=bool) if supplemented is None else supplemented
    return {
        "freq_hz": float(row.freq_hz),
        "damping": float(row.damping),
        "damped_freq_hz": float(row.damped_freq_hz),
        "freq_ci95": [float(row.freq_ci95_lo), float(row.freq_ci95_hi)],
        "damping_ci95": [float(row.damping_ci95_lo), float(row.damping_ci95_hi)],
        "shape": {
            s: {"mag": float(abs(v)), "phase_deg": float(np.degrees(np.angle(v))), "supplemented": bool(f)}
            for s, v, f in zip(sensors, shape, flags, strict=True)
        },
    }


def modal_frf(freq_hz, freqs, dampings, shapes):
    """Absolute-acceleration transmissibility synthesised from modes: ``sum r/(iw - lambda) + c.c.``
    with ``r = -lambda^2 M`` (M: EPFRF modal constants). Shape (n_freq, n_sensors)."""
    w = 2j * np.pi * np.asarray(freq_hz)[:, None, None]
    wn = 2 * np.pi * np.asarray(freqs)
    lam = -np.asarray(dampings) * wn + 1j * wn * np.sqrt(1 - np.asarray(dampings) ** 2)
    r = -(lam**2)[None, :] * shapes  # (n_sensors, n_modes)
    out = r[None] / (w - lam[None, None]) + np.conj(r)[None] / (w - np.conj(lam)[None, None])
    return out.sum(axis=2)


def mac(a: np.ndarray, b: np.ndarray) -> float:
    """The modal assurance criterion of two complex shape vectors, ``|a^H b|^2 / (|a|^2 |b|^2)``
    (0 where either is zero)."""
    den = np.vdot(a, a).real * np.vdot(b, b).real
    return float(abs(np.vdot(a, b)) ** 2 / den) if den > 0 else 0.0


def nearest_pole(freq_hz: np.ndarray, f: float) -> int:
    """The index of the pole of ``freq_hz`` (Hz) nearest ``f`` (Hz), by log ratio."""
    return int(np.argmin(np.abs(np.log(freq_hz / f))))


def matched_poles(old_hz: np.ndarray, new_hz: np.ndarray) -> list[tuple[int, int]]:
    """One-to-one pairs ``(i_new, j_old)`` of two pole sets' frequencies (Hz), nearest pairs
    first (by log ratio); the larger set's surplus poles stay unpaired."""
    pairs = sorted((abs(np.log(n / o)), i, j) for i, n in enumerate(new_hz) for j, o in enumerate(old_hz))
    taken_new, taken_old, out = set(), set(), []
    for _, i, j in pairs:
        if i not in taken_new and j not in taken_old:
            taken_new.add(i)
            taken_old.add(j)
            out.append((i, j))
    return out


def new_poles(old_hz: np.ndarray, new_hz: np.ndarray) -> list[int]:
    """The poles of ``new_hz`` (indices) left over when each of ``old_hz`` takes its nearest."""
    paired = {i for i, _ in matched_poles(old_hz, new_hz)}
    return [i for i in range(len(new_hz)) if i not in paired]
