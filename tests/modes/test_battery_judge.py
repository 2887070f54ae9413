"""The count battery's judge (``scripts/count_battery.py``), the measure of the selection's accuracy on
unseen bodies: right within max(2 %, 3 Cramer-Rao bounds), a close pair the bounds cannot separate
reported as one mode or as two, and no found mode counted for two exact ones."""

import importlib.util
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

_SPEC = importlib.util.spec_from_file_location(
    "count_battery", Path(__file__).resolve().parents[2] / "scripts" / "count_battery.py"
)
battery = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(battery)


def _selection(freq_hz, damping):
    f = np.asarray(freq_hz, float)
    modes = pd.DataFrame({"freq_hz": f, "damping": damping, "freq_ci95_lo": 0.99 * f, "freq_ci95_hi": 1.01 * f})
    return SimpleNamespace(modes=modes)


# seed 65537's five-segment #15: the 14.71 / 15.05 Hz pair has bounds of 18 and 11 %
TRUTH = SimpleNamespace(freq_hz=np.array([7.05, 9.07, 14.71, 15.05, 26.12]), damping=np.full(5, 0.3))
CRB_F, CRB_X = np.array([0.002, 0.004, 0.183, 0.111, 0.033]), np.full(5, 0.05)


@pytest.mark.parametrize(("found", "right"), [
    ([7.04, 9.04, 15.14, 25.41], True),  # the pair as one mode
    ([7.04, 9.04, 14.5, 15.3, 25.41], True),  # the pair as two
    ([7.04, 15.14, 25.41], False),  # 9.07 missed: no mode of the pair's stands in for it
    ([7.04, 8.2, 15.14, 25.41], False),  # 9.07 found 9.6 % off (bound 0.4 %)
    ([7.04, 9.04, 25.41], False),  # the pair missed
    ([7.04, 9.04, 12.0, 15.14, 18.0, 25.41], False),  # three modes for the pair
])  # fmt: skip
def test_a_wide_close_pair_takes_only_the_modes_nearest_it(found, right):
    ok, why = battery.judge(TRUTH, _selection(found, np.full(len(found), 0.3)), CRB_F, CRB_X, top_hz=24.0 / 0.9 + 10)
    assert ok is right, why
