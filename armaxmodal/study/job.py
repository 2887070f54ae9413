"""One recording of a study: stabilise, select, summarise -- a plain dict that pickles to any
worker and back, and is cached as JSON."""

from __future__ import annotations

import base64
import hashlib
import io
import json
import time
from dataclasses import asdict, dataclass

import numpy as np

from armaxmodal._version import __version__
from armaxmodal.exceptions import OrderError
from armaxmodal.recording import Recording

__all__ = ["StudySettings", "analyse_recording"]


@dataclass(frozen=True)
class StudySettings:
    """What every recording of a study goes through (recorded in ``study.json``).

    Attributes
    ----------
    input : str
        The base-acceleration channel.
    orders : (lo, hi) or None
        The swept AR orders (even steps), as ``stabilise --orders``; None: the default
        sweep, capped at what each record supports.
    modes : int or None
        Modes kept per recording (None: the automatic selection).
    band : (lo, hi) Hz or None
    detrend : {"mean", "linear", "none"}
    sensors : tuple of str or None
        The sensors analysed (None: those most recordings share, chosen by the study).
    lump : (a, b) or None
        A pair of segments to test for lumping (Chapter 5) where a recording has both.

    See Also
    --------
    armaxmodal.study.run_study : Takes them.
    armaxmodal.study.track_modes : Takes them too.

    Examples
    --------
    >>> from armaxmodal.study import StudySettings
    >>> settings = StudySettings(orders=(2, 20), lump=("legs", "feet"))
    >>> settings.orders, settings.detrend, settings.lump
    ((2, 20), 'mean', ('legs', 'feet'))
    """

    input: str = "base"
    orders: tuple[int, int] | None = None
    modes: int | None = None
    band: tuple[float, float] | None = None
    detrend: str = "mean"
    sensors: tuple[str, ...] | None = None
    lump: tuple[str, str] | None = None

    def to_dict(self) -> dict:
        return {**asdict(self), "armaxmodal_version": __version__}

    def key(self) -> str:
        """Hash of everything that changes a recording's result.

        Returns
        -------
        str
            The first 16 hex digits of the settings' SHA-256.
        """
        return hashlib.sha256(json.dumps(self.to_dict(), sort_keys=True).encode()).hexdigest()[:16]


def analyse_recording(rec: Recording, settings: StudySettings, sensors: tuple[str, ...]) -> dict:
    """Stabilisation diagram, automatic selection and the thumbnail of one recording.

    The modes come from ``sensors`` (the study's common set); the lumping check may use
    any of the recording's channels. Runs single-threaded (one BLAS thread, no inner process
    pool): the study parallelises over recordings, and the result is the same wherever it runs.

    Parameters
    ----------
    rec : Recording
    settings : StudySettings
    sensors : tuple of str
        The study's common sensors.

    Returns
    -------
    dict
        ``sensors``, ``fs``, ``analysis_fs``, ``nk``, ``modes`` (one dict per mode: frequency in
        Hz, damping ratio, 95 % intervals, Eq. 3.35-3.36 weighted values and the normalised shape
        per sensor), ``peak_input`` (the input's largest departure from its mean, in its own units),
        ``per_sensor`` (Table 3.2 rows), ``warnings``, ``reconstruction_error`` and
        ``quality`` (the modal-model check's misfit and verdict), ``lump`` and ``figure_png``
        (base64).

    See Also
    --------
    armaxmodal.study.run_study : Runs it on every recording.

    Examples
    --------
    One ride of the supine body, its modes over the exact ones (5.83, 8.31, 13.50, 16.25 Hz):

    >>> import numpy as np
    >>> import armaxmodal as am
    >>> from armaxmodal.study import StudySettings, analyse_recording
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)
    >>> result = analyse_recording(ride, StudySettings(orders=(2, 12)), ("head", "chest", "pelvis", "legs"))
    >>> found = np.array([mode["freq_hz"] for mode in result["modes"]])
    >>> result["quality"], np.round(found / am.supine_human().modes().freq_hz, 1)
    ('good', array([1., 1., 1., 1.]))
    """
    from armaxmodal._threads import one_blas_thread
    from armaxmodal.modes.diagram import stabilisation_diagram
    from armaxmodal.modes.pipeline import select_modes

    start = time.perf_counter()
    orders = None if settings.orders is None else range(settings.orders[0], settings.orders[1] + 1, 2)
    with one_blas_thread():  # the thumbnail and the lumping check too, not only the fits
        diagram = stabilisation_diagram(
            rec.select(sensors), orders, band=settings.band, detrend=settings.detrend, n_jobs=1
        )
        selection = select_modes(diagram, settings.modes, settings.band, n_jobs=1)
        if selection.modes.empty:  # a recording with no mode is a study's failure row, as before
            raise OrderError(selection.own_warnings[0].message)
        report = selection.to_dict("per_sensor")
        figure = _thumbnail(diagram, selection)
        lump = _lump(rec, settings)
    weighted = selection.weighted.set_index("mode")
    for i, mode in enumerate(report["modes"], start=1):
        mode["rank"] = i
        mode["freq_hz_weighted"] = float(weighted.freq_hz.get(i, np.nan))
        mode["damping_weighted"] = float(weighted.damping.get(i, np.nan))
    return {
        "sensors": list(sensors),
        "fs": report["fs"],
        "analysis_fs": report["analysis_fs"],
        "n_samples": rec.n_samples,
        "peak_input": float(np.max(np.abs(rec.base - rec.base.mean()))),  # about its mean: gravity is no shaking
        "nk": report["nk"],
        "modes": report["modes"],
        "per_sensor": report["per_sensor"],
        "warnings": report["warnings"],
        "reconstruction_error": report["reconstruction_error"],
        "quality": report["quality"],
        "lump": lump,
        "figure_png": figure,
        "seconds": time.perf_counter() - start,
    }


def _thumbnail(diagram, selection) -> str:
    import matplotlib.pyplot as plt

    ax, _ = diagram.plot(selection)
    buf = io.BytesIO()
    ax.figure.savefig(buf, format="png", dpi=72)
    plt.close(ax.figure)
    return base64.b64encode(buf.getvalue()).decode("ascii")


def _lump(rec: Recording, settings: StudySettings) -> dict | None:
    if settings.lump is None or not set(settings.lump) <= set(rec.sensors):
        return None
    from armaxmodal.lumping import lump_check

    return lump_check(rec, *settings.lump, wavelet=False).to_dict()
