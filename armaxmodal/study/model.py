"""The physical chain model of a study's average subject and its scaling to each subject
(thesis Section 4.4, Eqs. 4.5-4.7)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from armaxmodal.exceptions import ArmaxModalError
from armaxmodal.inverse import model_update, scale_to_subject
from armaxmodal.inverse.modal_data import body_mass_bounds, to_eigenvalues
from armaxmodal.systems.datasets import TABLE_4_2_MASS_FRACTION

__all__ = ["average_subject_models"]


def _mean_shapes(recordings: list[dict], modes: pd.DataFrame, ride: str, sensors, n_modes: int) -> np.ndarray:
    """Per mode, the mean over the ride's recordings of each complex shape (largest component
    1, real): the geometric mean of Fig. 3.7 keeps magnitudes only, a chain needs phases too."""
    total = np.zeros((len(sensors), n_modes), complex)
    count = np.zeros(n_modes)
    labels = modes[(modes.ride == ride)].dropna(subset=["mode"])
    for r in recordings:
        if r["ride"] != ride:
            continue
        mine = labels[labels.file == r["file"]]
        for rank, mode in zip(mine["rank"], mine["mode"], strict=True):
            shape = r["modes"][int(rank) - 1]["shape"]
            total[:, int(mode) - 1] += [
                shape[s]["mag"] * np.exp(1j * np.radians(shape[s]["phase_deg"])) for s in sensors
            ]
            count[int(mode) - 1] += 1
    return total / np.maximum(count, 1)


def average_subject_models(study) -> tuple[list[dict], list[dict]]:
    """Per ride, a chain fitted (:func:`armaxmodal.inverse.model_update`) to the across-subject
    mean modes and mean shapes, at the subjects' mean mass; then that chain scaled to every
    subject with a mass (Eq. 4.7: M, C, K times m_subject / m_model).

    Returns
    -------
    models : list of dict
        One per ride: components (kg, N/m, N s/m), the model's modes, flags; or the reason
        it could not be built.
    scaled : list of dict
        One row per ride, subject and component (tidy: ``ride, subject, mass_kg, component,
        value``). Subjects without a mass are listed in the model's ``unscaled``.
    """
    t = study.tables
    sensors = list(study.sensors)
    bounds = (
        body_mass_bounds(sensors, TABLE_4_2_MASS_FRACTION) if set(sensors) <= set(TABLE_4_2_MASS_FRACTION) else None
    )
    models, scaled = [], []
    for ride, summary in t.summary.groupby("ride"):
        summary = summary.sort_values("mode")
        masses = t.modes[t.modes.ride == ride].groupby("subject").mass_kg.first()
        entry = {"ride": ride, "modes_used": summary["mode"].tolist()}
        n_modes = int(summary["mode"].max())
        if list(summary["mode"]) != list(range(1, n_modes + 1)) or masses.isna().all():
            entry["reason"] = "needs every mode 1..N in the summary and subjects with a mass_kg"
            models.append(entry)
            continue
        try:
            lam = to_eigenvalues(summary.freq_hz_mean, summary.damping_mean)
            shapes = _mean_shapes(study.recordings, t.modes, ride, sensors, n_modes)
            mean_mass = float(masses.mean())
            sol = model_update(
                lam,
                shapes,
                mass_ratio_bounds=bounds,
                total_mass=mean_mass,
                names=sensors,
                shape_magnitude_only=True,
                sigma={"shape": 0.2},
            )
        except ArmaxModalError as exc:
            entry["reason"] = str(exc)
            models.append(entry)
            continue
        comps = sol.components
        entry.update(
            mass_kg=mean_mass,
            components={"masses": comps.masses, "k": comps.k, "c": comps.c, "k_s": comps.k_s, "c_s": comps.c_s},
            model_modes=sol.modes.to_frame().to_dict("records"),
            flags=list(sol.flags),
            unscaled=sorted(masses[masses.isna()].index),
        )
        models.append(entry)
        for subject, mass in masses.dropna().items():
            sub = scale_to_subject(sol.structure, float(mass)).chain_components()
            for name in ("masses", "k", "c", "k_s", "c_s"):
                for i, v in enumerate(getattr(sub, name), start=1):
                    scaled.append(
                        {
                            "ride": ride,
                            "subject": subject,
                            "mass_kg": float(mass),
                            "component": f"{name}{i}",
                            "value": float(v),
                        }
                    )
    return models, scaled
