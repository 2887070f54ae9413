"""Use and check a physical model: scale it to a subject (Eqs. 4.5-4.7) and predict every
sensor under a measured base input (Section 4.5.2, Figs. 4.8-4.9)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from armaxmodal.exceptions import DataError
from armaxmodal.recording import Recording
from armaxmodal.systems.simulation import simulate
from armaxmodal.systems.structure import Structure


def scale_to_subject(structure: Structure, mass_kg: float) -> Structure:
    """Multiply M, C and K by ``alpha = m_subject / m_model`` (Eq. 4.7): same modes, the
    subject's mass.

    Parameters
    ----------
    structure : Structure
        The identified (or average) model.
    mass_kg : float
        The subject's mass.

    Returns
    -------
    Structure
        The scaled model.

    See Also
    --------
    armaxmodal.inverse.InverseSolution : The model it scales.
    armaxmodal.study.run_study : Scales the average subject with ``model=True``.

    Examples
    --------
    >>> import armaxmodal as am
    >>> from armaxmodal.inverse import scale_to_subject
    >>> body = am.supine_human()  # Section 4.4's chain, 77.6 kg
    >>> subject = scale_to_subject(body, 80.0)
    >>> round(float(subject.masses.sum()), 1), [round(float(f), 2) for f in subject.modes().freq_hz]  # the same modes
    (80.0, [5.83, 8.31, 13.5, 16.25])
    """
    if not (np.isfinite(mass_kg) and mass_kg > 0):
        raise DataError(f"mass_kg: expected a positive subject mass in kg, got {mass_kg!r}.")
    alpha = mass_kg / structure.masses.sum()
    return Structure(structure.M * alpha, structure.C * alpha, structure.K * alpha, structure.names)


def predict_recording(structure: Structure, recording: Recording, hold: str = "bandlimited") -> pd.DataFrame:
    """Each sensor's absolute acceleration predicted from the measured base acceleration.

    Returns a frame with, per sensor, the NRMSE fit in percent
    ``100 (1 - |y - y_hat| / |y - mean y|)`` and the correlation; the predicted signals are in
    ``frame.attrs["prediction"]`` ((n_samples, n_sensors)).

    Parameters
    ----------
    structure : Structure
        The chain model; its DOF names must include the recording's sensors.
    recording : Recording
        A measured ride.
    hold : {"bandlimited", "zoh"}
        How the input behaves between samples.

    Returns
    -------
    pandas.DataFrame
        One row per sensor: ``fit_percent`` and ``correlation``.

    See Also
    --------
    armaxmodal.inverse.InverseSolution : The model it simulates.
    armaxmodal.simulate_recording : The simulation underneath.

    Examples
    --------
    >>> import armaxmodal as am
    >>> from armaxmodal.inverse import predict_recording
    >>> body = am.supine_human()
    >>> ride = am.simulate_recording(body, am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03, seed=2)
    >>> table = predict_recording(body, ride, hold="zoh")  # the model that made the ride, 3 % noise on it
    >>> [round(float(v)) for v in table.fit_percent]  # per sensor, %
    [97, 97, 97, 97]
    """
    missing = [s for s in recording.sensors if s not in structure.names]
    if missing:
        raise DataError(f"sensors {missing} are not DOFs of the model {list(structure.names)}.")
    y_hat = simulate(structure, recording.base, recording.fs, hold=hold)
    idx = [structure.names.index(s) for s in recording.sensors]
    y_hat = y_hat[:, idx]
    y = recording.response
    err = np.linalg.norm(y - y_hat, axis=0)
    ref = np.linalg.norm(y - y.mean(axis=0), axis=0)
    corr = [float(np.corrcoef(y[:, k], y_hat[:, k])[0, 1]) for k in range(y.shape[1])]
    frame = pd.DataFrame({"sensor": recording.sensors, "fit_percent": 100 * (1 - err / ref), "correlation": corr})
    frame.attrs["prediction"] = y_hat
    return frame
