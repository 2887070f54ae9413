"""Coerce and check user input; every message says expected vs got and the fix."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from armaxmodal.exceptions import DataError, StructureError


def as_signal_matrix(x, name: str, channel_names: Sequence[str] | None = None) -> np.ndarray:
    """Return ``x`` as a C-contiguous float64 array of shape (n_samples, n_channels).

    A 1-D input becomes one column. NaN or inf raise :class:`DataError` naming the channel
    and the first bad sample; complex samples raise too (casting would drop the imaginary part).
    """
    if np.iscomplexobj(x):
        raise DataError(
            f"{name}: expected real samples, got complex ones; pass the real part if that is what was measured."
        )
    try:
        arr = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise DataError(f"{name}: expected numeric samples, got {type(x).__name__} ({exc}).") from exc
    if arr.ndim == 1:
        arr = arr[:, None]
    if arr.ndim != 2:
        raise DataError(f"{name}: expected shape (n_samples,) or (n_samples, n_channels), got {arr.shape}.")
    if arr.shape[0] == 0 or arr.shape[1] == 0:
        raise DataError(f"{name}: the signal is empty (shape {arr.shape}).")
    bad = ~np.isfinite(arr)
    if bad.any():
        col = int(np.argmax(bad.any(axis=0)))
        rows = np.flatnonzero(bad[:, col])
        label = channel_names[col] if channel_names is not None else f"column {col}"
        raise DataError(
            f"{name}: channel '{label}' has {rows.size} NaN/inf value(s), first at sample "
            f"{rows[0]}; interpolate or trim them before using the signal."
        )
    return np.ascontiguousarray(arr)


def as_signal_vector(x, name: str) -> np.ndarray:
    """Return ``x`` as a contiguous float64 vector of shape (n_samples,)."""
    arr = as_signal_matrix(x, name)
    if arr.shape[1] != 1:
        raise DataError(f"{name}: expected one channel, got shape {np.shape(x)}.")
    return np.ascontiguousarray(arr[:, 0])


def check_fs(fs) -> float:
    """Return the sampling rate as a positive finite float (Hz)."""
    try:
        value = float(fs)
    except (TypeError, ValueError) as exc:
        raise DataError(f"fs: expected a sampling rate in Hz, got {fs!r}.") from exc
    if not np.isfinite(value) or value <= 0:
        raise DataError(f"fs: expected a positive sampling rate in Hz, got {fs!r}.")
    return value


#: Largest |sample| a recording may hold, in any unit: the fits square and cube samples
#: (variances, a cubic spring's regressor), which overflow double precision near 1e150;
#: no physical reading in SI units or g comes near either bound.
MAX_AMPLITUDE = 1e30
#: Smallest largest-|sample| of a channel that is not all zero: below it the squares
#: underflow (near 1e-160) and every variance reads zero.
MIN_AMPLITUDE = 1e-30


def check_amplitude(x: np.ndarray, name: str, channel_names: Sequence[str] | None = None) -> None:
    """Raise :class:`DataError` if a channel of ``x`` (n, K) holds samples beyond
    ``MAX_AMPLITUDE`` or, not all zero, none above ``MIN_AMPLITUDE``: units off by many orders
    of magnitude (a raw integer stream scaled twice, a unit exponent lost on export)."""
    peak = np.max(np.abs(x), axis=0)
    bad = (peak > MAX_AMPLITUDE) | ((peak > 0) & (peak < MIN_AMPLITUDE))
    if not bad.any():
        return
    col = int(np.argmax(bad))
    label = channel_names[col] if channel_names is not None else f"column {col}"
    raise DataError(
        f"{name}: channel '{label}' has its largest |sample| at {peak[col]:.3g}, outside "
        f"{MIN_AMPLITUDE:g} to {MAX_AMPLITUDE:g}: the fits square and cube samples, which overflow or "
        "underflow double precision. Give the data in physical units (m/s^2 or g) or rescale the channel."
    )


def check_not_constant(x: np.ndarray, name: str) -> None:
    """Raise if a signal carries no variation (a constant input identifies nothing)."""
    span = np.ptp(x, axis=0)
    scale = np.max(np.abs(x), axis=0)
    flat = span <= 1e-12 * np.maximum(scale, 1e-300)
    if np.any(flat):
        raise DataError(
            f"{name} is constant (value {float(np.ravel(x)[0]):.6g}): a constant input excites "
            "nothing and the model is not identifiable; check that the right column is the input."
        )


def check_outputs_carry_signal(names, y: np.ndarray) -> None:
    """Raise :class:`DataError` naming the outputs (columns of ``y``) that are constant."""
    flat = [s for s, col in zip(names, y.T, strict=True) if np.ptp(col) <= 1e-12 * max(np.abs(col).max(), 1e-300)]
    if flat:
        raise DataError(f"sensor(s) {flat} carry no signal (constant); check the cable or drop them with outputs=.")


def as_square_matrix(a, name: str, n: int | None = None) -> np.ndarray:
    """Return a finite float64 square matrix, optionally of size ``n``."""
    try:
        arr = np.array(a, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise StructureError(f"{name}: expected a numeric square matrix ({exc}).") from exc
    if arr.ndim == 1:
        arr = np.diag(arr) if name == "M" else arr
    if arr.ndim != 2 or arr.shape[0] != arr.shape[1]:
        raise StructureError(f"{name}: expected a square matrix, got shape {arr.shape}.")
    if n is not None and arr.shape[0] != n:
        raise StructureError(f"{name}: expected shape ({n}, {n}) to match M, got {arr.shape}.")
    if not np.all(np.isfinite(arr)):
        raise StructureError(f"{name}: contains NaN or inf.")
    return arr
