"""Reference structures and published numbers from the source thesis.

- :func:`chapter2_system`: the four-DOF system of Section 2.3.1 (Table 2.1).
- :func:`supine_human`: the four-DOF supine-human chain of Section 4.4 (Tables 4.3-4.4).

The C matrix printed in Section 4.4 is not symmetric (a 0 stands where -40.29 belongs) and
its c_s2 entry reads 50.30 while Table 4.4 and the printed diagonal both give 45.3; with
45.3 the model reproduces Table 4.3 to its printed digits, so that is what is used here.
"""

from __future__ import annotations

import numpy as np

from .structure import Structure

__all__ = [
    "chapter2_system",
    "supine_human",
    "SUPINE_SENSORS",
    "TABLE_2_1",
    "TABLE_4_1",
    "TABLE_4_2_MASS_FRACTION",
    "TABLE_4_3",
    "TABLE_4_4",
    "MEAN_SUBJECT_MASS_KG",
]

SUPINE_SENSORS = ("head", "chest", "pelvis", "legs")

#: Table 2.1: undamped natural frequency (Hz) and damping ratio of the Chapter 2 system.
TABLE_2_1 = {"freq_hz": (5.92, 9.77, 13.33, 19.40), "damping": (0.28, 0.39, 0.36, 0.35)}

#: Table 4.1 (= Table 3.3 averages): measured modal parameters, mean of 15 subjects.
TABLE_4_1 = {
    "freq_hz": (5.0841, 7.8056, 11.0065, 15.4150),
    "damping": (0.1432, 0.2657, 0.2625, 0.2370),
    "freq_sd_hz": (0.5293, 0.7404, 0.9566, 1.2806),
    "damping_sd": (0.0341, 0.0734, 0.1224, 0.1023),
}

#: Table 4.2: segment mass / total body mass.
TABLE_4_2_MASS_FRACTION = {"head": 0.081, "chest": 0.272, "pelvis": 0.325, "legs": 0.322}

#: Section 4.4: mean body mass of the 15 subjects (kg).
MEAN_SUBJECT_MASS_KG = 76.96

#: Table 4.3: modes of the supine-human model of Section 4.4.
TABLE_4_3 = {
    "freq_hz": (5.8317, 8.3052, 13.5045, 16.2457),
    "damping": (0.2568, 0.3518, 0.3015, 0.2711),
    "damped_freq_hz": (5.6361, 7.7742, 12.8761, 15.6373),
}

#: Table 4.4: springs (N/m) and dampers (N s/m) of the supine-human chain.
TABLE_4_4 = {
    "k": (40707, 18152, 116596, 1059),
    "k_s": (20992, 36921, 37109),
    "c": (300.8, 727.6, 1122.5, 161.3),
    "c_s": (40.3, 45.3, 267.0),
}


def chapter2_system() -> Structure:
    """The four-DOF base-excited system of Section 2.3.1 (kg, N s/m, N/m)."""
    m = np.diag([6.0, 14.0, 22.0, 9.0])
    c = np.array(
        [
            [500.0, -80.0, 0.0, 0.0],
            [-80.0, 753.0, -163.0, 0.0],
            [0.0, -163.0, 1183.0, -165.0],
            [0.0, 0.0, -165.0, 211.0],
        ]
    )
    k = np.array(
        [
            [88000.0, -14000.0, 0.0, 0.0],
            [-14000.0, 59000.0, -17000.0, 0.0],
            [0.0, -17000.0, 148800.0, -11000.0],
            [0.0, 0.0, -11000.0, 13400.0],
        ]
    )
    return Structure(m, c, k, ("m1", "m2", "m3", "m4"))


def supine_human() -> Structure:
    """The supine-human chain of Section 4.4 (head, chest, pelvis, legs), symmetric C."""
    m = np.diag([6.2338, 21.3693, 30.0144, 19.9488])
    c = np.array(
        [
            [341.13, -40.29, 0.0, 0.0],
            [-40.29, 813.18, -45.3, 0.0],
            [0.0, -45.3, 1434.80, -266.96],
            [0.0, 0.0, -266.96, 428.26],
        ]
    )
    k = np.array(
        [
            [61699.0, -20992.0, 0.0, 0.0],
            [-20992.0, 76065.0, -36921.0, 0.0],
            [0.0, -36921.0, 190627.0, -37109.0],
            [0.0, 0.0, -37109.0, 38169.0],
        ]
    )
    return Structure(m, c, k, SUPINE_SENSORS)
