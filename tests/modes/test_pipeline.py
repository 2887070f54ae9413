"""The selection as named stages (armaxmodal.modes.pipeline): one recording visits each stage of
its list once, in order; each stage runs alone on a state; the settings reach the stages and come
back on the result and in the JSON."""

from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

import armaxmodal as am
from armaxmodal.modes import pipeline
from armaxmodal.modes.settings import (
    AgreementSettings,
    ClusterSettings,
    CountSettings,
    DftSettings,
    FrfSettings,
    NoteSettings,
    SelectionSettings,
)
from armaxmodal.modes.state import SelectionContext, SelectionState
from armaxmodal.quality_warnings import QualityWarning
from tests.cli.test_schemas import _validator

AUTOMATIC = ["candidates", "merge", "refit", "propose_by_frf", "count", "check", "spread", "separate", "finish"]


@pytest.fixture(scope="module")
def diagram(fixtures_dir):
    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    return am.stabilisation_diagram(rec, orders=range(4, 17, 2), n_jobs=1)


def _traced(diagram, **kwargs):
    entered = []
    selection = am.select_modes(diagram, n_jobs=1, on_stage=entered.append, **kwargs)
    return entered, selection


def test_one_recording_visits_each_stage_once_in_order(diagram):
    entered, selection = _traced(diagram)
    assert entered == AUTOMATIC
    assert [s.__name__ for s in pipeline.AUTOMATIC] == AUTOMATIC
    assert selection.count is not None and len(selection.modes) == 4  # the count ran and kept the four modes
    # what ran is said by typed fields, not by which columns the modes table happens to hold
    assert (selection.counted, selection.segments, selection.picks) == (True, pipeline.N_SEGMENTS, None)
    assert {"count_undecided", "interval_covers_other_estimator"} <= set(selection.to_dict()["modes"][0])
    # the count's and the estimators' flags, as the modes table holds them, mode by mode
    flags = {"count_undecided": "count_undecided", "structure_widened": "interval_covers_other_counts",
             "estimator_widened": "interval_covers_other_estimator", "model_error_dominates": "model_error_dominates"}
    for column, key in flags.items():
        flagged = replace(selection, modes=selection.modes.assign(**{column: [True, False, False, True]}))
        assert [m[key] for m in flagged.to_dict()["modes"]] == [True, False, False, True], key
    # each mode's spread over the segments, as the modes table holds it
    spread = [m["segment_spread"] for m in selection.to_dict()["modes"]]
    assert [s["segments_found"] for s in spread] == selection.modes.segments_found.tolist() == [pipeline.N_SEGMENTS] * 4
    assert [s["freq_sd_hz"] for s in spread] == selection.modes.freq_segment_sd.tolist()


def test_the_arguments_choose_a_named_stage_list(diagram):
    fixed, selection = _traced(diagram, n_modes=2, segments=0)
    assert fixed == ["candidates", "merge", "best_n", "refit", "check", "spread", "separate", "finish"]
    assert len(selection.modes) == 2 and selection.count is None  # the count does not run on a fixed number
    assert (selection.counted, selection.segments) == (False, 0)
    assert not {"count_undecided", "segment_spread"} & set(selection.to_dict()["modes"][0])
    halves = am.select_modes(diagram, n_modes=2, segments=2, n_jobs=1)  # the fewest segments a spread has
    assert halves.segments == 2 and halves.to_dict()["modes"][0]["segment_spread"]["segments_found"] <= 2
    plain, selection = _traced(diagram, refine=False, segments=0)
    assert plain == ["candidates", "merge", "segment_fits", "screen_by_frf", "check", "spread", "separate", "finish"]
    assert selection.refinement is None and selection.count is None
    picked, selection = _traced(diagram, picks=[8.3], segments=0)
    assert picked == ["take_picks", "candidates", "merge", "refit", "propose_by_frf", "count", "add_picks",
                      "check", "spread", "separate", "finish"]  # fmt: skip
    assert selection.picks == [8.3] and selection.counted
    with pytest.raises(am.PickError, match="do not mix"):
        pipeline.stages_for(2, [8.3], True)


def test_a_pick_the_diagram_does_not_offer_stops_before_any_fit(diagram):
    entered = []
    with pytest.raises(am.PickError):
        am.select_modes(diagram, picks=[2.0, 2.05], on_stage=entered.append)  # two picks in one cluster's reach
    assert entered == []  # refused while the picks are checked, before the first stage


def _state(freq, damping, support, shapes):
    modes = pd.DataFrame({"freq_hz": freq, "damping": damping, "support": support, "count": [10] * len(freq),
                          "energy": [1.0] * len(freq)})  # fmt: skip
    return SelectionState(modes, np.asarray(shapes, dtype=complex))


def test_merge_alone_drops_the_weaker_half_of_a_split_mode_and_orders_by_frequency(diagram):
    ctx = SelectionContext(diagram, SelectionSettings(), None, [4, 6])
    # 10.0 and 10.3 Hz lie within each other's half-power band (2 x 0.05 x 10 = 1 Hz) with one shape
    state = _state([20.0, 10.3, 10.0], [0.02, 0.05, 0.05], [0.9, 0.5, 0.8],
                   [[1, 1, 1], [0, 1, 1], [1, 0.5, 0.5], [0, 1, 1]])  # fmt: skip
    out = pipeline.merge(state, ctx)
    assert out.modes.freq_hz.tolist() == [10.0, 20.0]
    np.testing.assert_array_equal(out.shapes, state.shapes[:, [2, 0]])
    # shapes that differ (MAC below merge_mac) keep both
    loose = SelectionContext(diagram, SelectionSettings(cluster=ClusterSettings(merge_mac=0.999)), None, [4, 6])
    other = replace(state, shapes=np.array([[1, 1, 1], [0, 1, 0.2], [1, 0.5, 1], [0, 1, 0]], dtype=complex))
    assert pipeline.merge(other, loose).modes.freq_hz.tolist() == [10.0, 10.3, 20.0]


def test_best_n_alone_keeps_the_best_supported(diagram):
    ctx = SelectionContext(diagram, SelectionSettings(), None, [4, 6], n_modes=2)
    state = _state([5.0, 8.0, 13.0], [0.2, 0.3, 0.3], [0.9, 0.3, 0.6], np.eye(3))
    assert pipeline.best_n(state, ctx).modes.freq_hz.tolist() == [5.0, 13.0]


def test_separate_alone_notes_a_pair_whose_difference_holds_zero_at_95_percent(diagram):
    ctx = SelectionContext(diagram, SelectionSettings(), None, [4])

    def pair(apart_hz):  # the difference's SD is 0.1 sqrt(2) = 0.141 Hz
        modes = pd.DataFrame({"freq_hz": [10.0, 10.0 + apart_hz], "damping": [0.02, 0.02], "freq_sd": [0.1, 0.1],
                              "damping_sd": [0.001, 0.001]})  # fmt: skip
        return SelectionState(modes, np.eye(2, dtype=complex))

    assert pipeline.separate(pair(0.28), ctx).warnings == ()  # 1.98 SD: its 95 % interval excludes zero
    (note,) = pipeline.separate(pair(0.27), ctx).warnings  # 1.91 SD
    assert note.code == "modes_not_separated" and "1.9 standard deviations" in note.message


def test_count_alone_needs_the_refit(diagram):
    ctx = SelectionContext(diagram, SelectionSettings(), None, [4, 6])
    state = _state([5.0], [0.2], [0.9], np.ones((4, 1)))
    assert pipeline.count(state, ctx) is state  # no refinement: the modal model has no hold to fit under
    # a mode the FRF's check doubted is then not counted: its note stands, said once
    note = QualityWarning("mode_not_needed", (), "a stable pole at 7.000 Hz is left out", 7.0)
    doubted = pipeline.count(replace(state, doubts=((7.0, 0.1, note),)), ctx)
    assert doubted.doubts == () and doubted.warnings == (note,)
    # and a proposal at an unexplained peak is not added: nothing is, without the count
    proposed = replace(state, proposals=((7.0, 0.1),))
    assert pipeline.count(proposed, ctx) is proposed


def test_check_alone_judges_the_modes_it_is_given(diagram):
    ctx = SelectionContext(diagram, SelectionSettings(), None, sorted({o.na for o in diagram.orders}), segments=0)
    exact = am.supine_human().modes()
    modes = pd.DataFrame({"freq_hz": exact.freq_hz, "damping": exact.damping})
    state = pipeline.check(SelectionState(modes, np.ones((4, 4), dtype=complex)), ctx)
    assert state.check.passed and state.result is None  # the exact modes explain the ride's FRF
    np.testing.assert_allclose(np.sort(np.abs(state.check.poles) / (2 * np.pi)), np.sort(exact.freq_hz))
    # where one row reports a pair, the check fits the model's two poles
    pair = replace(state, check_poles=((5.8, 0.26), (8.3, 0.35)), modes=modes.iloc[[0]], shapes=np.ones((4, 1)))
    assert len(pipeline.check(pair, ctx).check.poles) == 2


def test_the_stages_run_one_by_one_give_select_modes_result(diagram):
    whole = am.select_modes(diagram, n_jobs=1, segments=0)
    ctx = SelectionContext(diagram, SelectionSettings(), None, sorted({o.na for o in diagram.orders}), segments=0,
                           n_jobs=1)  # fmt: skip
    state = SelectionState.empty(len(diagram.recording.sensors))
    for stage in pipeline.AUTOMATIC[:-1]:
        state = stage(state, ctx)
        assert state.result is None
    done = pipeline.finish(state, ctx).result
    pd.testing.assert_frame_equal(done.modes, whole.modes)
    assert [w.message for w in done.warnings] == [w.message for w in whole.warnings]


@pytest.mark.parametrize("where_hz, taken_back", [(20.0, False), (13.5, True)])
def test_a_doubt_is_offered_to_the_count_which_alone_keeps_or_drops_it(diagram, where_hz, taken_back):
    """A mode the FRF's check doubted is tried by the count as an addition (its table holds the
    trial). Where no mode is (20 Hz, damping 0.05) the count refuses it and its note is said once;
    the ride's own 13.5 Hz mode, taken out of the start as if doubted, the count takes back, and no
    note says it is not needed."""
    ctx = SelectionContext(diagram, SelectionSettings(), None, sorted({o.na for o in diagram.orders}), segments=0,
                           n_jobs=1)  # fmt: skip
    state = SelectionState.empty(len(diagram.recording.sensors))
    for stage in (pipeline.candidates, pipeline.merge, pipeline.refit):
        state = stage(state, ctx)
    rows = state.modes.freq_hz.to_numpy()
    if taken_back:  # the 13.5 Hz mode out of the start, as the check drops one it does not need
        state = state.kept(np.flatnonzero(np.abs(rows / where_hz - 1) > 0.05))
    note = QualityWarning("mode_not_needed", (), f"a stable pole at {where_hz:.3f} Hz is left out", where_hz)
    counted = pipeline.count(replace(state, doubts=((where_hz, 0.3 if taken_back else 0.05, note),)), ctx)
    table = counted.count.models_table()
    assert np.any((table.action == "add") & (np.abs(table.freq_hz / where_hz - 1) < 0.01))
    said = [w for w in counted.warnings if w.code == "mode_not_needed"]
    reported = counted.modes.freq_hz.to_numpy()
    if taken_back:
        assert said == [] and np.any(np.abs(reported / where_hz - 1) < 0.03)
    else:
        assert said == [note] and not np.any(np.abs(reported / where_hz - 1) < 0.1)


def test_settings_reach_the_stages_and_come_back_on_the_result(diagram):
    default = am.select_modes(diagram, n_jobs=1, segments=0)
    assert default.settings == SelectionSettings()
    # a cluster must hold poles of 8 orders where the sweep has 7: no mode is found, and it says why
    strict = SelectionSettings(cluster=ClusterSettings(min_orders=8))
    none = am.select_modes(diagram, n_jobs=1, segments=0, settings=strict)
    assert none.modes.empty and none.settings is strict
    assert "a mode needs 8" in next(w.message for w in none.warnings if w.code == "no_modes")
    with pytest.raises(TypeError, match="SelectionSettings"):
        am.select_modes(diagram, settings={"cluster": {"freq": 0.03}})


def test_the_frf_and_note_settings_reach_the_check_and_the_notes(diagram):
    default = am.select_modes(diagram, n_jobs=1, segments=0)
    worst = float(default.check.model_error.max())  # 0.005 on this ride
    # a limit below the ride's own model error: the same modes no longer explain the FRF
    tight = SelectionSettings(frf=FrfSettings(model_error_limit=worst / 2))
    strict = am.select_modes(diagram, n_jobs=1, segments=0, refine=False, settings=tight)
    assert strict.check.limit == worst / 2 and not strict.check.passed and strict.quality == "poor"


def test_the_oversampling_note_follows_its_settings():
    from armaxmodal.prepare.resample import oversampling_note

    def note(freq_hz, fs, settings=None):  # as the finish stage passes them
        s = NoteSettings() if settings is None else settings
        return oversampling_note(np.array(freq_hz), fs, s.oversampled_fraction, s.suggested_band_factor)

    (said,) = note([5.0, 12.0], 1000.0)  # 12 Hz of a 500 Hz Nyquist: 2.4 %
    assert "band=(0, 30)" in said.message and said.value == pytest.approx(0.024)  # 2.5 x 12 Hz
    (wider,) = note([12.0], 1000.0, NoteSettings(suggested_band_factor=5.0))
    assert "band=(0, 60)" in wider.message
    assert note([12.0], 1000.0, NoteSettings(oversampled_fraction=0.02)) == []
    # a share so large that the band suggested keeps the rate: nothing to suggest (it divided by zero)
    assert note([16.2], 60.0, NoteSettings(oversampled_fraction=0.6)) == []


def test_the_json_carries_its_settings(diagram):
    import json

    selection = am.select_modes(diagram, n_jobs=1, segments=0,
                                settings=SelectionSettings(count=CountSettings(decisive_bic=12.0)))  # fmt: skip
    out = json.loads(json.dumps(selection.to_dict(), allow_nan=False))
    assert out["settings"]["count"]["decisive_bic"] == 12.0
    assert out["settings"]["cluster"]["freq"] == 0.05 and out["settings"]["lines"]["undamped"] == 2e-3
    assert out["settings"]["frf"]["model_error_limit"] == 0.5 and out["settings"]["dft"]["min_damping"] == 1e-4
    _validator("stabilise").validate(out)


def test_a_wrong_settings_part_is_refused():
    with pytest.raises(TypeError, match="settings.count: expected a CountSettings"):
        SelectionSettings(count=ClusterSettings())


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: CountSettings(decisive_bic=-1.0),
         r"CountSettings.decisive_bic: expected a positive number, got -1.0 \(the default is 10.0\)"),
        (lambda: ClusterSettings(min_support=1.2),
         "ClusterSettings.min_support: a probability, share or MAC is at most 1"),
        (lambda: CountSettings(max_steps=2.5), "CountSettings.max_steps: expected a whole number, got 2.5"),
        (lambda: FrfSettings(model_error_limit=float("nan")),
         "FrfSettings.model_error_limit: expected a positive number"),
        (lambda: ClusterSettings(freq=True), "ClusterSettings.freq: expected a number, got True"),
        (lambda: DftSettings(min_damping=0.5, max_damping=0.4), "min_damping .0.5. must lie below max_damping"),
        (lambda: AgreementSettings(alpha=1.5), "AgreementSettings.alpha: a probability, share or MAC is at most 1"),
    ],
)
def test_a_threshold_no_setting_can_take_is_refused_by_name(make, message):
    with pytest.raises(am.SettingsError, match=message):
        make()
    # at the limits, accepted
    assert ClusterSettings(min_support=1.0).min_support == 1.0 and CountSettings(max_steps=1).max_steps == 1


def test_settings_print_what_was_tuned_and_signatures_stay_short():
    """A default settings object prints as its bare constructor (the API's signatures read
    ``settings=SelectionSettings()``, not every threshold); a tuned one names the tuned value and
    no other, nested or not; the value still round-trips through ``eval``."""
    from armaxmodal.modes.settings import CountSettings, SelectionSettings, SweepSettings

    assert repr(SelectionSettings()) == "SelectionSettings()" and repr(SweepSettings()) == "SweepSettings()"
    tuned = SelectionSettings(count=CountSettings(decisive_bic=20.0), cluster=ClusterSettings(min_orders=8))
    assert repr(tuned) == (
        "SelectionSettings(cluster=ClusterSettings(min_orders=8), count=CountSettings(decisive_bic=20.0))"
    )
    namespace = {"SelectionSettings": SelectionSettings, "CountSettings": CountSettings,
                 "ClusterSettings": ClusterSettings}  # fmt: skip
    assert eval(repr(tuned), namespace) == tuned
