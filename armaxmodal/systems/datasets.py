"""Reference structures and published numbers from the source thesis.

- :func:`~armaxmodal.chapter2_system`: the four-DOF system of Section 2.3.1 (Table 2.1).
- :func:`~armaxmodal.supine_human`: the four-DOF supine-human chain of Section 4.4 (Tables 4.3-4.4).

The C matrix printed in Section 4.4 is not symmetric (a 0 stands where -40.29 belongs) and
its c_s2 entry reads 50.30 while Table 4.4 and the printed diagonal both give 45.3; with
45.3 the model reproduces Table 4.3 to its printed digits, so that is what is used here.
"""

from __future__ import annotations

import numpy as np

from armaxmodal.systems.structure import Structure

__all__ = [
    "chapter2_system",
    "five_mass_chain",
    "supine_human",
    "supine_with_feet",
    "SUPINE_SENSORS",
    "TABLE_2_1",
    "TABLE_3_3_SUBJECTS",
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

#: Table 3.3: per subject, |M|-weighted undamped frequency (Hz, modes 1-4) and damping ratio
#: (modes 1-4) of the 15 supine subjects; the printed Average and SD rows follow from these.
TABLE_3_3_SUBJECTS = (
    (5.7480, 8.1363, 9.8456, 14.2988, 0.2053, 0.1455, 0.3770, 0.2438),
    (4.2896, 7.8828, 9.8628, 16.9895, 0.1084, 0.2507, 0.1748, 0.1839),
    (5.1909, 7.6597, 11.3091, 14.6065, 0.1271, 0.1950, 0.1410, 0.1326),
    (5.4348, 8.0596, 10.1002, 17.0228, 0.1294, 0.1854, 0.3576, 0.2381),
    (5.3890, 7.1576, 10.7109, 13.5626, 0.1417, 0.3151, 0.1436, 0.1522),
    (5.0496, 7.1635, 11.7524, 14.4954, 0.2042, 0.3146, 0.2588, 0.4513),
    (5.0305, 6.9894, 10.3053, 16.5492, 0.1101, 0.1886, 0.5362, 0.2170),
    (3.9958, 8.8048, 11.4552, 14.9223, 0.1419, 0.2194, 0.2142, 0.1417),
    (4.7380, 8.0569, 12.8226, 16.3769, 0.1333, 0.2673, 0.2658, 0.3661),
    (4.8669, 7.7138, 12.6320, 15.1035, 0.1448, 0.2903, 0.2318, 0.2393),
    (4.8400, 7.4722, 10.1365, 16.5344, 0.1140, 0.2302, 0.3906, 0.3684),
    (5.5889, 9.5558, 11.1890, 16.1642, 0.1564, 0.4144, 0.0490, 0.0658),
    (4.8288, 6.5801, 10.2300, 16.8020, 0.1323, 0.3609, 0.3395, 0.1886),
    (6.0096, 7.6085, 10.9834, 14.5427, 0.1017, 0.2910, 0.1931, 0.2694),
    (5.2609, 8.2426, 11.7630, 13.2547, 0.1977, 0.3172, 0.2650, 0.2962),
)

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
    """The four-DOF base-excited system of Section 2.3.1 (kg, N s/m, N/m).

    Returns
    -------
    Structure

    See Also
    --------
    armaxmodal.supine_human : The four-segment supine chain of Section 4.4.

    Examples
    --------
    >>> import numpy as np
    >>> import armaxmodal as am
    >>> system = am.chapter2_system()
    >>> system.n_dof, np.round(system.modes().freq_hz, 1).tolist()
    (4, [5.9, 9.8, 13.3, 19.4])
    """
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
    """The supine-human chain of Section 4.4 (head, chest, pelvis, legs), symmetric C.

    Returns
    -------
    Structure

    See Also
    --------
    armaxmodal.supine_with_feet : The same chain with a light feet segment.
    armaxmodal.chapter2_system : The four-DOF system of Section 2.3.1.

    Examples
    --------
    >>> import numpy as np
    >>> import armaxmodal as am
    >>> body = am.supine_human()
    >>> body.names
    ('head', 'chest', 'pelvis', 'legs')
    >>> np.round(body.modes().freq_hz, 2)  # Table 4.3's natural frequencies, Hz
    array([ 5.83,  8.31, 13.5 , 16.25])
    """
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


def supine_with_feet() -> Structure:
    """Table 4.4's supine chain with a light feet segment on the legs (2.5 kg; to the base
    40 kN/m and 250 N s/m, to the legs 20 kN/m and 60 N s/m; not from the thesis, which
    names the feet as an optional fifth sensor): modes 6.89, 8.36, 13.54, 16.25 and
    24.84 Hz, damping 0.26-0.40, the fifth near the 28 Hz edge of the thesis's rides.

    Returns
    -------
    Structure

    See Also
    --------
    armaxmodal.supine_human : The four-segment supine chain of Section 4.4.

    Examples
    --------
    >>> import numpy as np
    >>> import armaxmodal as am
    >>> body = am.supine_with_feet()
    >>> body.names
    ('head', 'chest', 'pelvis', 'legs', 'feet')
    >>> np.round(body.modes().freq_hz, 1)
    array([ 6.9,  8.4, 13.5, 16.2, 24.8])
    """
    return Structure.from_chain(
        [6.2338, 21.3693, 30.0144, 19.9488, 2.5],
        [40707.0, 18152.0, 116596.0, 1059.0, 40000.0],
        [300.8, 727.6, 1122.5, 161.3, 250.0],
        [20992.0, 36921.0, 37109.0, 20000.0],
        [40.3, 45.3, 267.0, 60.0],
        SUPINE_SENSORS + ("feet",),
    )


def five_mass_chain() -> Structure:
    """A five-mass chain (not from the thesis): modes 6.56, 7.66, 9.75, 11.09 and 14.42 Hz
    at 7-10 % damping, some close. The size benchmark's structure (``benchmarks/bench_size.py``);
    at ``na = 10`` its shared-pole ARMAX model is over-parameterised and its fit crawls."""
    return Structure.from_chain(
        [8.0, 10.0, 30.0, 15.0, 12.0],
        [2e4, 1e4, 5e4, 3e4, 2e4],
        [60.0, 40.0, 180.0, 100.0, 80.0],
        [2e4, 3e4, 2e4, 1e4],
        [40.0, 60.0, 40.0, 20.0],
        ("head", "chest", "pelvis", "thighs", "legs"),
    )
