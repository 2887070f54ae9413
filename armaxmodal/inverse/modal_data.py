"""Validation of modal data handed to the inverse methods."""

from __future__ import annotations

import numpy as np

from armaxmodal.exceptions import StructureError


def check_modes(eigenvalues, shapes, n_dof: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Return (lambda (n_modes,), psi (n_dof, n_modes)) as complex arrays, or raise.

    Eigenvalues are continuous poles in rad/s with positive imaginary part (under-damped);
    shapes have one column per mode and no missing components.
    """
    lam = np.atleast_1d(np.asarray(eigenvalues, dtype=complex))
    psi = np.asarray(shapes, dtype=complex)
    if psi.ndim != 2 or psi.shape[1] != lam.size:
        raise StructureError(f"shapes: expected shape (n_dof, {lam.size}) for {lam.size} modes, got {psi.shape}.")
    if n_dof is not None and psi.shape[0] != n_dof:
        raise StructureError(f"shapes: expected {n_dof} components per mode, got {psi.shape[0]}.")
    if not (np.all(np.isfinite(lam)) and np.all(np.isfinite(psi))):
        raise StructureError(
            "modal data contain NaN or inf (a missing shape component?); fill gaps first "
            "(armaxmodal.modes.result.supplement_shapes) or drop that sensor."
        )
    if np.any(lam.imag <= 1e-9 * np.abs(lam)):
        raise StructureError(
            "a real or lower-half-plane eigenvalue was given: over-damped modes carry no oscillation "
            "and the chain model here needs under-damped poles (positive imaginary part)."
        )
    return lam, psi


def to_eigenvalues(freq_hz, damping) -> np.ndarray:
    """Continuous poles from undamped frequency (Hz) and damping ratio."""
    wn = 2 * np.pi * np.asarray(freq_hz, dtype=float)
    x = np.asarray(damping, dtype=float)
    if np.any(x >= 1) or np.any(x < 0):
        raise StructureError(f"damping ratios must lie in [0, 1) for under-damped modes, got {x}.")
    return -x * wn + 1j * wn * np.sqrt(1 - x**2)


def body_mass_bounds(sensors, fractions: dict, spread: tuple[float, float] = (0.7, 1.2)) -> list[tuple[float, float]]:
    """Mass-ratio bounds ``m_j / m_1`` from segment mass fractions (Table 4.2).

    The thesis's bounds (Section 4.3.3: 2.35-4.03, 2.81-4.81, 2.78-4.77 for chest, pelvis and
    legs over head) are the table's ratios times about 0.7 and 1.2; ``spread`` sets those.
    """
    missing = [s for s in sensors if s not in fractions]
    if missing:
        raise StructureError(f"no mass fraction for {missing}; known segments: {sorted(fractions)}.")
    base = fractions[sensors[0]]
    return [(spread[0] * fractions[s] / base, spread[1] * fractions[s] / base) for s in sensors[1:]]


def modes_from_json(data: dict) -> tuple[np.ndarray, np.ndarray, list]:
    """Eigenvalues, shapes (n_sensors, n_modes) and sensor names from the stabilise JSON."""
    try:
        sensors = list(data["outputs"])
        modes = data["modes"]
        lam = to_eigenvalues([m["freq_hz"] for m in modes], [m["damping"] for m in modes])
        shapes = np.array(
            [
                [m["shape"][s]["mag"] * np.exp(1j * np.radians(m["shape"][s]["phase_deg"])) for m in modes]
                for s in sensors
            ]
        )
    except (KeyError, TypeError) as exc:
        raise StructureError(f"modes JSON: missing field {exc}; write it with 'armaxmodal stabilise --json'.") from exc
    except ValueError as exc:  # a frequency, damping or shape entry that is not a number
        raise StructureError(
            f"modes JSON: a value is not a number ({exc}); write it with 'armaxmodal stabilise --json'."
        ) from exc
    return lam, shapes, sensors
