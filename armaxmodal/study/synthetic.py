"""A synthetic study with known truth: subjects varying like the thesis's, two rides each.

Each subject is the Section 4.4 supine chain scaled to a body mass drawn from the thesis's
76.96 +- 8.71 kg (Eq. 4.7 scaling leaves the modes unchanged), with every spring and damper
perturbed so the modes spread like Tables 3.2-3.3. Some subjects carry a feet sensor:
rigidly attached to the legs for most (the feet record the legs' motion with their own
sensor noise), a separate mass hung from the legs for the ones named in ``separate_feet``
(Chapter 5's question, with a known answer).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from armaxmodal.io.write import write_json, write_recording_csv
from armaxmodal.recording import Recording
from armaxmodal.systems.datasets import MEAN_SUBJECT_MASS_KG, TABLE_4_4
from armaxmodal.systems.simulation import add_noise, random_vibration, simulate, sine_sweep
from armaxmodal.systems.structure import Structure

__all__ = ["make_study", "subject_structure", "RIDES"]

RIDES = ("sweep", "random")
BODY = ("head", "chest", "pelvis", "legs")
MASS_SD_KG = 8.71
MASS_FRACTION = (0.081, 0.272, 0.325, 0.322)  # Table 4.2
FEET_OF_LEGS = 0.099  # Section 5.4: feet / legs mass ratio
SPRING_SD, DAMPER_SD = 0.12, 0.20  # lognormal spreads giving Table 3.3-like mode spread
FEET_MODE_HZ, FEET_DAMPING = 9.0, 0.12  # the separate feet's own mode on fixed legs


def subject_structure(rng: np.random.Generator, mass_kg: float, separate_feet: bool = False) -> Structure:
    """One subject's chain: Table 4.4 scaled to ``mass_kg`` and perturbed, redrawn until its
    four body modes are under-damped (damping < 0.5), between 3 and 22 Hz and 15 % apart."""
    alpha = mass_kg / MEAN_SUBJECT_MASS_KG
    for _ in range(100):
        k = alpha * np.array(TABLE_4_4["k"], float) * rng.lognormal(0, SPRING_SD, 4)
        k_s = alpha * np.array(TABLE_4_4["k_s"], float) * rng.lognormal(0, SPRING_SD, 3)
        c = alpha * np.array(TABLE_4_4["c"], float) * rng.lognormal(0, DAMPER_SD, 4)
        c_s = alpha * np.array(TABLE_4_4["c_s"], float) * rng.lognormal(0, DAMPER_SD, 3)
        masses = mass_kg * np.array(MASS_FRACTION)
        body = Structure.from_chain(masses, k, c, k_s, c_s, BODY)
        modes = body.modes()
        f, z = modes.freq_hz, modes.damping
        if (
            f.size == 4
            and np.all(z < 0.5)
            and 3.0 < f[0]
            and f[-1] < 22.0
            and np.all(f[1:] / f[:-1] > 1.15)
            and modes.real_poles.size == 0
        ):
            break
    else:  # pragma: no cover - the spreads above redraw a handful of times at most
        raise RuntimeError("no admissible subject in 100 draws")
    if not separate_feet:
        return body
    m_feet = FEET_OF_LEGS * masses[3]
    masses = np.append(masses[:3], [masses[3] - m_feet, m_feet])
    w = 2 * np.pi * FEET_MODE_HZ
    k_f, c_f = m_feet * w**2, 2 * FEET_DAMPING * m_feet * w
    return Structure.from_chain(
        masses, np.append(k, 0.0), np.append(c, 0.0), np.append(k_s, k_f), np.append(c_s, c_f), BODY + ("feet",)
    )


def body_modes(structure: Structure) -> pd.DataFrame:
    """The four body modes: with a separate feet mass, its own mode (the one in which the
    feet move most against the legs) is left out."""
    modes = structure.modes()
    keep = np.arange(modes.freq_hz.size)
    if structure.n_dof == 5:
        apart = np.abs(modes.shapes[4] - modes.shapes[3]) / np.abs(modes.shapes).max(axis=0)
        keep = np.delete(keep, int(np.argmax(apart)))
    return pd.DataFrame({"mode": np.arange(1, 5), "freq_hz": modes.freq_hz[keep], "damping": modes.damping[keep]})


def _ride(structure: Structure, ride: str, fs: float, duration: float, feet: str | None, rng) -> tuple:
    if ride == "sweep":
        u = sine_sweep(fs, duration, 0.5, 20.0, amplitude=2.0, power_exponent=1.0)
    else:
        u = random_vibration(fs, duration, (0.5, 28.0), rms=1.0, seed=int(rng.integers(2**31)))
    y = simulate(structure, u, fs, hold="bandlimited")
    names = list(structure.names)
    if feet == "rigid":  # the feet sensor rides on the legs
        y = np.column_stack([y, y[:, 3]])
        names.append("feet")
    y = add_noise(y, 0.05, rng)
    return add_noise(u[:, None], 0.01, rng)[:, 0], y, names


def make_study(
    out: str | Path,
    n_subjects: int = 15,
    *,
    feet_subjects: tuple[int, ...] = (7, 8, 9, 10, 11, 12),
    separate_feet: tuple[int, ...] = (12,),
    rides: tuple[str, ...] = RIDES,
    fs: float = 60.0,
    duration: float = 120.0,
    seed: int = 2024,
) -> dict:
    """Write ``n_subjects`` x ``rides`` CSV recordings, ``manifest.csv`` and ``truth.json``.

    Subjects are numbered from 1; ``feet_subjects`` carry a feet sensor, rigid unless also in
    ``separate_feet``. Returns the truth: per subject its mass, feet, chain and body modes,
    and per ride the across-subject mean and sample SD of the modes (Table 3.3 form).

    Parameters
    ----------
    out : str or Path
        The folder to write (created).
    n_subjects : int
    feet_subjects : tuple of int
        Subjects with a feet sensor.
    separate_feet : tuple of int
        Subjects whose feet move on their own spring (others' feet are rigid).
    rides : tuple of {"sweep", "random"}
    fs : float
        Sampling rate, Hz.
    duration : float
        Length of each ride, s.
    seed : int

    Returns
    -------
    dict
        The truth written to ``truth.json``.

    See Also
    --------
    armaxmodal.study.run_study : Analyse what it writes.

    Examples
    --------
    >>> import tempfile
    >>> from armaxmodal.study import make_study
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     truth = make_study(folder, 2, feet_subjects=(), separate_feet=(), rides=("random",), duration=30.0)
    >>> len(truth["subjects"]), truth["fs"], truth["duration_s"]
    (2, 60.0, 30.0)
    """
    out = Path(out)
    rng = np.random.default_rng(seed)
    rows, subjects = [], []
    for i in range(1, n_subjects + 1):
        name = f"Sub{i:02d}"
        mass = float(np.clip(rng.normal(MEAN_SUBJECT_MASS_KG, MASS_SD_KG), 50.0, 110.0))
        feet = None if i not in feet_subjects else ("separate" if i in separate_feet else "rigid")
        structure = subject_structure(rng, mass, separate_feet=feet == "separate")
        modes = body_modes(structure)
        subjects.append(
            {
                "subject": name,
                "mass_kg": mass,
                "feet": feet,
                "modes": modes.to_dict("records"),
                "M": structure.M,
                "C": structure.C,
                "K": structure.K,
                "names": list(structure.names),
            }
        )
        for ride in rides:
            u, y, names = _ride(structure, ride, fs, duration, feet, rng)
            rec = Recording(fs, u, y, names, subject=name, mass_kg=mass)
            file = f"{name}_{ride}.csv"
            write_recording_csv(rec, out / file, float_format="%.8g")
            rows.append({"file": file, "subject": name, "ride": ride, "mass_kg": round(mass, 3), "feet": feet or ""})
    pd.DataFrame(rows).to_csv(out / "manifest.csv", index=False)
    truth = {"subjects": subjects, "summary": _truth_summary(subjects, rides), "fs": fs, "duration_s": duration}
    write_json(truth, out / "truth.json")
    return truth


def _truth_summary(subjects: list[dict], rides) -> list[dict]:
    f = np.array([[m["freq_hz"] for m in s["modes"]] for s in subjects])
    z = np.array([[m["damping"] for m in s["modes"]] for s in subjects])
    return [
        {
            "ride": ride,
            "mode": r + 1,
            "freq_hz_mean": f[:, r].mean(),
            "freq_hz_sd": f[:, r].std(ddof=1),
            "damping_mean": z[:, r].mean(),
            "damping_sd": z[:, r].std(ddof=1),
            "n": len(subjects),
        }
        for ride in rides
        for r in range(4)
    ]
