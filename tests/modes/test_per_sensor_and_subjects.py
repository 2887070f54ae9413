import dataclasses

import numpy as np
import pytest

import armaxmodal as am
from armaxmodal.exceptions import DataError
from armaxmodal.modes.diagram import stabilisation_diagram
from armaxmodal.modes.pipeline import select_modes
from armaxmodal.modes.result import supplement_shapes
from armaxmodal.study.tables import summarise_subjects
from armaxmodal.systems import datasets

# Table 3.3 prints four decimals.
TABLE_ATOL = 0.6e-4
# The implementation against Eq. 3.34 evaluated with the exact transmissibility: limited by the
# H1 estimate (four 30 s averages for a fine grid, 5 % output and 1 % input noise), seen
# here at up to 4.7 %.
EQ_3_34_RTOL = 0.06
# Against the true shape: Eq. 3.33 is a near-resonance approximation; on this lightly damped
# chain the exact transmissibility ratio is within 3 % of the true shape ratio in magnitude but
# up to 13.5 degrees off in phase (mode 3: the neighbouring modes' tails), hence these bounds.
SUPPLEMENT_RTOL = 0.10
SUPPLEMENT_PHASE_DEG = 20.0


def test_summary_reproduces_table_3_3():
    import pandas as pd

    rows = np.array(datasets.TABLE_3_3_SUBJECTS)
    weighted = [pd.DataFrame({"freq_hz": r[:4], "damping": r[4:]}) for r in rows]
    table = summarise_subjects(weighted)["table"]
    np.testing.assert_allclose(
        table.loc["Average"], [5.0841, 7.8056, 11.0065, 15.4150, 0.1432, 0.2657, 0.2625, 0.2370], atol=TABLE_ATOL
    )
    np.testing.assert_allclose(
        table.loc["SD"], [0.5293, 0.7404, 0.9566, 1.2806, 0.0341, 0.0734, 0.1224, 0.1023], atol=TABLE_ATOL
    )
    np.testing.assert_allclose(table.loc["Average"].iloc[:4], datasets.TABLE_4_1["freq_hz"], atol=TABLE_ATOL)


def test_summary_refuses_mismatched_modes_and_gives_geometric_mean_shapes():
    import pandas as pd

    a = pd.DataFrame({"freq_hz": [5.0, 8.0], "damping": [0.2, 0.3]})
    b = pd.DataFrame({"freq_hz": [5.0], "damping": [0.2]})
    with pytest.raises(DataError, match="same number"):
        summarise_subjects([a, b])
    shapes = [np.array([[1.0, 0.5], [0.25, 1.0]]), np.array([[1.0, 2.0], [1.0, 4.0]])]
    out = summarise_subjects([a, a], shapes)
    np.testing.assert_allclose(out["shape_geomean"], [[1.0, 0.5], [0.5, 1.0]])


@pytest.fixture(scope="module")
def light_selection():
    structure = am.Structure.from_chain(
        [1.0, 1.5, 2.0], [2e4, 1e4, 3e4], [2.0, 1.5, 3.0], [1.5e4, 1e4], [1.0, 1.0], ("a", "b", "c")
    )
    u = am.random_vibration(100.0, 120.0, (0.5, 45.0), seed=7)
    rec = am.simulate_recording(structure, u, 100.0, noise=0.05, input_noise=0.01, seed=8, hold="bandlimited")
    return structure, select_modes(stabilisation_diagram(rec))


def test_supplement_fills_a_removed_component_from_the_transmissibility(light_selection):
    structure, selection = light_selection
    truth = structure.modes().modal_constants
    table = selection.per_sensor.copy()
    own, flags = supplement_shapes(selection)
    assert not flags.any()  # every sensor shows every mode here
    for mode in range(3):
        gap = table.index[(table["sensor"] == "c") & (table["mode"] == mode + 1)]
        damaged = table.copy()
        damaged.loc[gap, "own_modal_constant"] = np.nan + 0j
        filled, flags = supplement_shapes(dataclasses.replace(selection, per_sensor=damaged))
        assert flags[2, mode] and flags.sum() == 1
        t = structure.transmissibility([structure.modes().damped_freq_hz[mode]])[0]
        known = own[:2, mode]
        ell, q = np.argsort(-np.abs(known))[:2]
        scale = abs(known[q] / known[ell]) / abs(t[q] / t[ell])
        expected = t[2] / t[ell] * scale * known[ell]
        assert abs(filled[2, mode] / expected - 1) < EQ_3_34_RTOL
        ratio = filled[2, mode] / filled[0, mode]
        true_ratio = truth[2, mode] / truth[0, mode]
        assert abs(abs(ratio) / abs(true_ratio) - 1) < SUPPLEMENT_RTOL
        assert abs(np.degrees(np.angle(ratio / true_ratio))) < SUPPLEMENT_PHASE_DEG
        # the components the sensors showed are untouched
        np.testing.assert_array_equal(filled[:2, mode], own[:2, mode])


def test_json_per_sensor_shapes_flag_supplemented(light_selection):
    """The JSON flags exactly the component Eq. (3.34) filled (sensor c's own model made to miss
    mode 2), and no other; the shared shapes are never flagged. (This test once never saw the
    flag set.)"""
    _, selection = light_selection
    data = selection.to_dict("per_sensor")
    assert all(not c["supplemented"] for m in data["modes"] for c in m["shape"].values())
    table = selection.per_sensor.copy()
    table.loc[(table["sensor"] == "c") & (table["mode"] == 2), "own_modal_constant"] = np.nan + 0j
    damaged = dataclasses.replace(selection, per_sensor=table)
    flagged = [(m, s) for m, mode in enumerate(damaged.to_dict("per_sensor")["modes"], start=1)
               for s, c in mode["shape"].items() if c["supplemented"]]  # fmt: skip
    assert flagged == [(2, "c")]
    assert not any(c["supplemented"] for m in damaged.to_dict()["modes"] for c in m["shape"].values())
    with pytest.raises(ValueError, match="shapes"):
        selection.to_dict("other")
