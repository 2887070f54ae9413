"""Modes picked by hand (``select_modes(picks=...)``, ``stabilise --pick``): against the exact modes
of the bundled supine ride, and every way a pick can be wrong refused with its reason."""

import json
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

import armaxmodal as am
from armaxmodal.cli.main import main
from armaxmodal.modes.clusters import check_picks
from armaxmodal.modes.counted import _picked_result
from armaxmodal.modes.mode_count import ModeCount
from armaxmodal.modes.settings import ClusterSettings, CountSettings, SelectionSettings
from armaxmodal.modes.state import SelectionState


@pytest.fixture(scope="module")
def ride(fixtures_dir):
    """The bundled supine ride (exact modes 5.83, 8.31, 13.50, 16.25 Hz) and its diagram."""
    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    return am.supine_human().modes(), am.stabilisation_diagram(rec, range(2, 21, 2), per_sensor=False)


def test_three_picks_are_the_three_exact_modes_and_the_fourth_is_said_to_be_there(ride):
    exact, diagram = ride
    sel = am.select_modes(diagram, picks=[13.6, 5.9, 8.2], segments=0)
    assert sel.picks == [5.9, 8.2, 13.6] and sel.modes.picked_hz.tolist() == [5.9, 8.2, 13.6]
    np.testing.assert_allclose(sel.modes.freq_hz, exact.freq_hz[:3], rtol=0.02)
    np.testing.assert_allclose(sel.modes.damping, exact.damping[:3], rtol=0.15)
    assert sel.count is not None and sel.count.steps == ()  # the number of modes is the user's
    # each pick is needed; the mode not picked stays in the model (without it, 13.50 Hz came out at
    # 15.77, standing for both) and is named
    assert not [w for w in sel.warnings if w.code == "pick_not_supported"]
    (other,) = [w for w in sel.warnings if w.code == "mode_count" and "not picked" in w.message]
    assert other.value == 1 and "16.2" in other.message
    assert sel.check.passed and len(sel.check.residues[0]) == 4  # the check judges the model: 4 modes
    # the picks are reported from the model the selection carries (the picks' fit, not the automatic search's)
    assert set(sel.modes.freq_hz) <= set(sel.count.model.freq_hz) and sel.counted
    record = sel.to_dict()
    assert record["picks"] == [5.9, 8.2, 13.6] and all(m["picked"] for m in record["modes"])
    assert am.select_modes(diagram, segments=0).to_dict()["picks"] is None


@pytest.mark.parametrize(
    "picks, kwargs, message",
    [
        ([11.0], {}, r"pick 11 Hz: no stable cluster of the diagram within 5 % \(the nearest is at"),
        ([5.8, 30.0], {}, r"picks \[30.0\] Hz lie at or above the Nyquist frequency .30 Hz"),
        ([5.8, 5.9], {}, r"within 5 % of each other"),
        ([5.8, -1.0], {}, r"positive number"),
        ([], {}, r"no frequency given"),
        ([5.8], {"n_modes": 2}, r"do not mix"),
    ],
)
def test_a_pick_the_diagram_does_not_offer_is_refused_with_the_reason(ride, picks, kwargs, message):
    with pytest.raises(am.PickError, match=message):
        am.select_modes(ride[1], picks=picks, segments=0, **kwargs)


def test_picks_are_checked_against_the_band_and_nyquist():
    assert check_picks([8.0, 5.0], (1.0, 20.0), 60.0).tolist() == [5.0, 8.0]
    with pytest.raises(am.PickError, match="Nyquist frequency .30 Hz"):
        check_picks([31.0], None, 60.0)
    with pytest.raises(am.PickError, match="the band 1-20 Hz"):
        check_picks([0.5], (1.0, 20.0), 60.0)
    reach = ClusterSettings().pick_reach
    assert check_picks([10.0, 10.0 * (1 + reach) * 1.001], None, 60.0).size == 2  # just apart
    # the reach is the clustering's: a narrower clustering lets closer picks stand apart
    assert check_picks([10.0, 10.4], None, 60.0, ClusterSettings(freq=0.03)).size == 2


def test_a_pick_the_modal_model_takes_out_of_the_band_is_reported_and_said():
    """Three modes in the model, two picked: the model keeps the 5 Hz pick and takes the 9 Hz pick
    to 20 Hz, so that pick is reported as the selection had it, tentative, with the reason; the
    12 Hz mode not picked stays in the model, unreported, and is named."""
    modes = pd.DataFrame({"freq_hz": [5.0, 9.0, 12.0], "damping": [0.1, 0.05, 0.05], "count": [6, 4, 5],
                          "picked_hz": [5.1, 9.0, np.nan]})  # fmt: skip
    work = SelectionState(modes, np.array([[1.0, 2.0, 5.0]], dtype=complex))
    model = SimpleNamespace(
        freq_hz=np.array([5.1, 20.0, 12.1]), damping=np.array([0.1, 1e-4, 0.05]), freq_sd=np.full(3, 0.01),
        damping_sd=np.array([0.001, 0.0, 0.001]), shapes=np.array([[3.0, 4.0, 6.0]], dtype=complex), n_modes=3,
        nyquist_hz=30.0, at_bound=None, damping_floor=1e-4,
    )  # fmt: skip

    count = ModeCount(model, model, (), np.array([80.0, -3.0, 60.0]), -50.0, np.nan, 1.0)
    verdicts = count.verdicts((1.0, 25.0))
    assert verdicts.tolist() == ["needed", "not_a_mode", "needed"]  # the 20 Hz pole is a line
    out = _picked_result(work, count, verdicts != "not_a_mode", verdicts, "bandlimited", SelectionSettings())
    assert out.modes.freq_hz.tolist() == [5.1, 9.0] and out.shapes.tolist() == [[3.0, 2.0]]
    assert out.modes.count_undecided.tolist() == [False, True] and out.modes.picked_hz.tolist() == [5.1, 9.0]
    (said,) = [n for n in out.warnings if n.code == "pick_not_supported"]
    assert "9.000 Hz to 20.000 Hz" in said.message
    (other,) = [n for n in out.warnings if n.code == "mode_count"]
    assert other.value == 1 and "12.100 Hz" in other.message


def test_stabilise_pick_from_the_command_line(fixtures_dir, tmp_path, capsys):
    data = str(fixtures_dir / "supine_random.csv")
    out = tmp_path / "modes.json"
    assert main(["--quiet", "stabilise", data, "--orders", "2:20", "--pick", "5.9,8.2", "--json", str(out)]) == 0
    capsys.readouterr()  # the run's own warnings
    record = json.loads(out.read_text())
    assert record["picks"] == [5.9, 8.2] and [round(m["freq_hz"], 1) for m in record["modes"]] == [5.8, 8.3]
    for argv, message in (
        (["--pick", "5.9", "--modes", "2"], "--pick and --modes do not mix"),
        (["--pick", "5.9,eight"], "--pick: expected frequencies in Hz"),
        (["--pick", "45"], "at or above the Nyquist frequency"),
        (["--pick", "25", "--band", "2:20"], "outside the band 2-20 Hz"),
    ):
        assert main(["--quiet", "stabilise", data, *argv]) == 2
        err = capsys.readouterr().err
        assert message in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_a_pick_the_record_does_not_need_is_said():
    """Two kept picks: without the first the criterion rises by 4 only (under 10), without the second by 80."""
    from armaxmodal.modes.notes import pick_notes as _pick_notes

    model = SimpleNamespace(freq_hz=np.array([5.0, 9.0]), damping=np.array([0.1, 0.05]), freq_sd=np.full(2, 0.01),
                            damping_sd=np.full(2, 0.001), nyquist_hz=30.0, at_bound=None,
                            damping_floor=1e-4)  # fmt: skip
    count = ModeCount(model, model, (), np.array([4.0, 80.0]), -30.0, 7.0, 1.0, settings=CountSettings())
    (note,) = _pick_notes(count, np.array([True, True]))
    assert note.code == "pick_not_supported" and note.value == 5.0 and "+4.0" in note.message
    assert _pick_notes(count, np.array([False, True])) == []  # only the picked poles are judged


def test_the_picks_model_keeps_the_poles_the_automatic_model_hides(ride):
    """A pole the automatic model holds beyond the band (it stands for the modes above it) stays in
    the model the picks are fitted with: leaving it out biases the top picks."""
    from dataclasses import replace

    import armaxmodal.modes.counted as counted

    _, diagram = ride
    sel = am.select_modes(diagram, segments=0)
    m = sel.count.model  # the pole added at 40 Hz is beyond the band by its interval too (+-1 Hz)
    beyond = SimpleNamespace(freq_hz=np.r_[m.freq_hz, 40.0], damping=np.r_[m.damping, 0.1],
                             freq_sd=np.r_[m.freq_sd, 0.5], damping_sd=np.r_[m.damping_sd, 0.01],
                             nyquist_hz=m.nyquist_hz, at_bound=np.r_[m.at_bound, False],
                             damping_floor=m.damping_floor)  # fmt: skip
    modes = sel.modes.assign(picked_hz=[5.9, 8.2, np.nan, np.nan])
    count = replace(sel.count, model=beyond, removal_rise=np.r_[sel.count.removal_rise, 50.0])  # one rise per pole
    work = SelectionState(modes, sel.shapes, sel.refinement, sel.check, count)
    seen = []

    def stop(data, freq_hz, damping, *args, search=True, **kwargs):
        seen.append((list(freq_hz), search))
        raise KeyboardInterrupt  # what was asked is all this test needs

    with pytest.raises(KeyboardInterrupt):
        counted.counted_modes(diagram, work, sel.refinement.band_hz, "bandlimited", [2, 4], SelectionSettings(),
                              picked=True, counter=stop)
    (starts, search), = seen
    assert starts[-1] == 40.0 and len(starts) == 5 and search is False
