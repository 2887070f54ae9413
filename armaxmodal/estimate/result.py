"""The result of a fit: :class:`~armaxmodal.ArmaxFit`, its models, losses, convergence, covariances and the
modes of its poles with their delta-method intervals.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from armaxmodal.armax import ArmaxModel
from armaxmodal.modal import pole_uncertainty
from armaxmodal.stats import Z95

__all__ = ["ArmaxFit"]

_MODE_COLUMNS = [
    "sensor",
    "freq_hz",
    "damping",
    "damped_freq_hz",
    "freq_ci95_lo",
    "freq_ci95_hi",
    "damping_ci95_lo",
    "damping_ci95_hi",
    "freq_sd",
    "damping_sd",
    "pole",
    "residue",
    "residue_mag",
    "residue_phase_deg",
]


@dataclass(frozen=True)
class ArmaxFit:
    """Result of :func:`~armaxmodal.fit_armax`.

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

    See Also
    --------
    armaxmodal.fit_armax : What makes one.
    armaxmodal.choose_orders : Orders for it by an information criterion.

    Examples
    --------
    >>> import armaxmodal as am
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)
    >>> fit = am.fit_armax(ride, 10, 10, 10, 0, shared_poles=True)  # na, nb, nc, nk
    >>> modes = fit.modes()  # one row per sensor and mode
    >>> modes[modes.sensor == "head"].freq_hz.round(1).tolist()  # exact: 5.83, 8.31, 13.50, 16.25 Hz
    [5.8, 8.3, 13.6, 16.2]
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

        Parameters
        ----------
        band : (lo, hi), optional
            Keep the poles whose frequency (Hz) lies in it (default: all).

        Returns
        -------
        pandas.DataFrame
            One row per sensor and pole, the columns above.
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
        """One row per sensor: orders, loss, noise variance, fit %, iterations, convergence.

        Returns
        -------
        pandas.DataFrame
            One row per sensor: its orders, loss, fit and convergence.
        """
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
