"""One fixed- or automatically-ordered identification: fit, physical modes, shapes, JSON.

The modes come from the shared-pole fit (every sensor sees the same poles); the per-sensor
table lists, for each mode, how strongly each sensor shows it (the residue magnitude).
Physical poles are those the stabilisation diagram's rejection rules keep (positive damping
up to ``max_damping``, away from 0 Hz and Nyquist, inside the excited band, non-negligible
residue), within ``band``; selection across orders lives in the stabilisation module.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import pandas as pd

from armaxmodal._threads import single_blas_thread
from armaxmodal.estimate.fit import fit_armax
from armaxmodal.estimate.orders import OrderChoice, choose_orders
from armaxmodal.estimate.result import ArmaxFit
from armaxmodal.io.write import finite_or_none
from armaxmodal.modal import mode_record
from armaxmodal.modes.modal_check import ModalCheck, check_modes
from armaxmodal.modes.poles import POLE_COLUMNS, SHARED, Tolerances, pole_rows, rejection_reasons
from armaxmodal.modes.result import record_header
from armaxmodal.modes.settings import DEFAULTS
from armaxmodal.prepare.preparation import Preparation, prepare
from armaxmodal.prepare.resample import oversampling_note
from armaxmodal.recording import Recording
from armaxmodal.stats import MAX_DAMPING

__all__ = ["identify", "Identification"]


@dataclass(frozen=True)
class Identification:
    """Modes of one recording.

    Attributes
    ----------
    fit : ArmaxFit
    modes : DataFrame
        One row per physical mode: freq_hz, damping, damped_freq_hz, CI bounds.
    shapes : (n_sensors, n_modes) complex ndarray
        EPFRF modal constants per sensor (Eq. 3.24), the mode-shape components.
    recording : Recording
        The record that was fitted (after preparation).
    order_table : DataFrame or None
        The criterion table when the orders were chosen automatically.
    preparation : Preparation or None
        What was done to the record before the fit, with the data-quality warnings.

    See Also
    --------
    armaxmodal.identify : What makes one.
    armaxmodal.ModeSelection : The modes of a whole sweep instead of one model.

    Examples
    --------
    >>> import armaxmodal as am
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)
    >>> result = am.identify(ride)
    >>> result.quality, result.modes.freq_hz.round(1).tolist()  # exact: 5.83, 8.31, 13.50, 16.25 Hz
    ('good', [5.8, 8.3, 13.6, 16.2])
    """

    fit: ArmaxFit
    modes: pd.DataFrame
    shapes: np.ndarray
    recording: Recording
    order_table: pd.DataFrame | None = None
    preparation: Preparation | None = None

    @cached_property
    def warnings(self) -> tuple:
        """Data-quality warnings found while preparing the record; ``unexplained_peak`` for
        each clear, coherent FRF peak no reported mode explains (as :func:`select_modes`
        gives: a fixed or BIC-chosen order can leave a mode out); and ``oversampled`` when
        every mode lies below a tenth of the Nyquist frequency (``oversampling_note``).
        Computed once (the peak check takes spectra)."""
        from armaxmodal.modes.frf import unexplained_peaks

        found = () if self.preparation is None else self.preparation.warnings
        band = None if self.preparation is None else self.preparation.band
        freq, damping = self.modes.freq_hz.to_numpy(), self.modes.damping.to_numpy()
        return (
            *found,
            *unexplained_peaks(self.recording, freq, damping, band),
            *oversampling_note(
                freq, self.recording.fs, DEFAULTS.notes.oversampled_fraction, DEFAULTS.notes.suggested_band_factor
            ),
            *self.check.warnings(),
        )

    @cached_property
    def check(self) -> ModalCheck:
        """The modal-model check of the reported modes (:func:`~armaxmodal.modes.check_modes`)."""
        band = None if self.preparation is None else self.preparation.band
        return check_modes(self.recording, self.modes.freq_hz.to_numpy(), self.modes.damping.to_numpy(), band)

    @property
    def quality(self) -> str:
        """``"good"`` when the modal-model check passes, else ``"poor"``."""
        return "good" if self.check.passed else "poor"

    def to_dict(self) -> dict:
        """The JSON contract: fs, input, outputs, modes (with shapes) and per_sensor rows.

        Returns
        -------
        dict
            Strict-JSON-ready (no NaN), as ``schemas/identify.schema.json`` describes.
        """
        rec = self.recording
        modes = [mode_record(row, self.shapes[:, i], rec.sensors) for i, row in enumerate(self.modes.itertuples())]
        per_sensor = [
            {
                "sensor": s,
                "mode": i + 1,
                "freq_hz": float(row.freq_hz),
                "damping": float(row.damping),
                "residue_mag": float(abs(self.shapes[k, i])),
            }
            for i, row in enumerate(self.modes.itertuples(index=False))
            for k, s in enumerate(rec.sensors)
        ]
        na, nb, nc, nk = self.fit.orders
        prep = self.preparation
        return {
            **record_header(rec, prep, self.warnings),
            "orders": {"na": na, "nb": nb, "nc": nc, "nk": nk, "shared_poles": self.fit.shared_poles},
            "converged": bool(np.all(self.fit.converged)),
            "fit_percent": dict(zip(rec.sensors, map(float, self.fit.fit_percent), strict=True)),
            "quality": self.quality,
            "reconstruction_error": finite_or_none(self.check.overall_error),
            "modal_check": self.check.to_dict(),
            "modes": modes,
            "per_sensor": per_sensor,
        }


@single_blas_thread
def identify(
    recording: Recording,
    orders: tuple[int, int, int, int] | None = None,
    *,
    band: tuple[float, float] | None = None,
    max_damping: float = MAX_DAMPING,
    progress: bool = False,
    detrend: str = "mean",
    resample: bool | None = None,
    align: bool = True,
    prepared: bool = False,
) -> Identification:
    """Fit the shared-pole ARMAX model and report its physical modes.

    Parameters
    ----------
    recording : Recording
    orders : (na, nb, nc, nk), optional
        Fixed orders; by default chosen by BIC (:func:`~armaxmodal.choose_orders`).
    band : (lo, hi), optional
        Frequency band of interest, Hz (default: 0 to 0.45 fs).
    max_damping : float
        Poles damped more than this are not reported as modes.
    progress : bool
        Show a progress bar during the automatic order search.
    detrend, align : see :func:`~armaxmodal.prepare.prepare`
        Each channel's mean is removed by default so gravity and offsets do not bias the modes.
    resample : bool, optional
        Resample to a rate suited to the band. Default: only when the orders are chosen
        automatically, because fixed orders belong to the record's own rate.
    prepared : bool
        The record is already prepared: fit it as it is (no checks, no warnings).

    Returns
    -------
    Identification

    See Also
    --------
    armaxmodal.fit_armax : The ARMAX fit alone.
    armaxmodal.stabilisation_diagram : Fits over a range of orders, for select_modes.

    Examples
    --------
    >>> import numpy as np
    >>> import armaxmodal as am
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 120.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)
    >>> result = am.identify(ride)  # orders chosen by BIC
    >>> exact = am.supine_human().modes().freq_hz  # 5.83, 8.31, 13.50, 16.25 Hz
    >>> round(100 * float(np.max(np.abs(result.modes.freq_hz / exact - 1))))  # the largest error, % (0.3-0.4)
    0
    """
    preparation = None
    if not prepared:
        if resample is None:
            resample = orders is None
        preparation = prepare(recording, band=band, detrend=detrend, resample=resample, align=align)
        recording = preparation.recording
    choice: OrderChoice | None = None
    if orders is None:
        choice = choose_orders(recording, progress=progress)
        fit = choice.fit
    else:
        fit = fit_armax(recording, *orders, shared_poles=True)
    # the same rejection rules as the stabilisation diagram (damping ceiling, 0 Hz and Nyquist,
    # the excited band, negligible residue), applied to this one order
    poles = pd.DataFrame(pole_rows(fit, SHARED), columns=POLE_COLUMNS)
    poles = poles[np.array(rejection_reasons(poles, Tolerances(), recording, max_damping)) == ""]
    if band is not None:
        poles = poles[(poles.freq_hz >= band[0]) & (poles.freq_hz <= band[1])]
    poles = poles.sort_values("freq_hz")
    shapes = np.column_stack(poles.vector.to_list()) if len(poles) else np.zeros((len(fit.models), 0))
    modes = poles.drop(columns=["source", "na", "energy", "vector"]).reset_index(drop=True)
    table = None if choice is None else choice.table
    return Identification(fit, modes, shapes, recording, table, preparation)
