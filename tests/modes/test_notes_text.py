"""The notes' texts, word for word, built from counts whose every field is known: a note is what a
user reads, so a number in the wrong place (the band's upper edge twice, a fall printed as a rise)
or a branch's words lost is a wrong result. Each expected text was read against the count it
describes when it was written (2026-11-29)."""

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from armaxmodal.modes import notes
from armaxmodal.modes.intervals import with_intervals
from armaxmodal.modes.mode_count import Adequacy, ModeCount, Step, Wanted
from armaxmodal.modes.settings import NoteSettings
from armaxmodal.prepare.resample import oversampling_note

BAND = (1.0, 25.0)
SAME_ROW = 0.05


def _model(freq, damping, sd=0.01):
    f, x = np.array(freq, float), np.array(damping, float)
    return SimpleNamespace(freq_hz=f, damping=x, freq_sd=sd * f, damping_sd=sd * x, n_modes=f.size, nyquist_hz=50.0,
                           at_bound=None, damping_floor=1e-4)


#: two reported modes (5 Hz needs only 4.5 to leave: undecided; 12 Hz needed) and a pole above the band
MODEL = _model((5.0, 12.0, 30.0), (0.2, 0.1, 0.9))
KEEP = np.array([True, True, False])


def _count(**changes) -> ModeCount:
    """A count holding one of everything a note is written from."""
    count = ModeCount(
        MODEL, MODEL, (Step("add", 12.5, 44.25, 13.5), Step("remove", 17.0, 12.5, float("nan"))),
        np.array([4.5, 80.0, 60.0]), -3.25, 21.5, 1.0, unconfirmed_hz=(14.25,),
        alternatives=((4.5, _model((5.02, 12.1), (0.21, 0.11))),), carried_away=((8.0, 9.5),),
        wanted=Wanted(23.5, 61.2, 12, 7.5, True), stand_ins=((26.0, 26.9, 15.2), (19.0, 19.8, 11.0)),
        unsettled_hz=(18.75,),
    )  # fmt: skip
    return replace(count, **changes)


def _said(found) -> list[tuple]:
    """Each note's code, value and text (a note of the count names no channel)."""
    assert all(n.channels == () for n in found)
    return [(n.code, n.value, n.message) for n in found]


def test_every_count_note_says_its_numbers_in_their_places():
    """Steps (one whose new pole moved), an undecided removal and addition, a wanted mode, a start
    carried away, an unsettled and an unconfirmed addition, intervals widened by an equally good
    model, stand-ins beyond and inside the band, and a pole outside it."""
    assert _said(notes.count_notes(_count(), KEEP, BAND, SAME_ROW)) == [
        ('mode_count', 12.5,
            'the mode at 12.500 Hz added (its new pole settled at 13.500 Hz): the information criterion (BIC) '
            'of the maximum-likelihood modal model, every pole free, falls by 44.2'),
        ('mode_count', 17.0,
            'the mode at 17.000 Hz left out: the information criterion (BIC) of the maximum-likelihood modal '
            'model, every pole free, falls by 12.5'),
        ('count_undecided', 4.5,
            'the record does not decide the number of modes: with one mode fewer (the rest refitted '
            "free) the criterion rises by only 4.5 (under 10, Kass & Raftery's 'very strong'); treat "
            'the weakest mode (5.000 Hz) as tentative'),
        ('count_undecided', 21.5,
            'the record does not rule out one mode more (near 21.500 Hz): adding it changes the '
            'criterion by +3.2, less than 10 either way'),
        ('count_undecided', 23.5,
            'the record may hold one mode more near 23.500 Hz: adding it raises the likelihood far '
            'beyond chance (likelihood ratio 61.2 for its 12 parameters, p < 1e-06) and the mode is '
            'the same in both halves of the record, but the criterion (BIC) rises by 7.5, so it is '
            'not reported; pick it (--pick) to see what the record says of it'),
        ('mode_count', 9.5,
            'the free fit carried the starting mode at 8.000 Hz to 9.500 Hz, where it is no mode '
            '(its damping unresolved, or not the same in both halves of the record); left out'),
        ('count_undecided', 18.75,
            "the mode at 18.750 Hz lowers the criterion decisively, but its frequency and damping in the "
            "record's two halves differ by more than chance allows at the 1 % level, though not by enough "
            "(1e-06) to call it a change during the record: it is reported, tentative; compare another "
            'record of the structure'),
        ('mode_count', 14.25,
            'one mode more near 14.250 Hz fits the whole record better but not each of its halves: a '
            'change during the record (a drifting frequency, a transient, a nonlinearity), not a '
            'mode; left out'),
        ('mode_count', 2.0,
            'the 95 % intervals of the mode(s) at 5.000, 12.000 Hz also cover their values in the '
            'models the record cannot tell from the chosen one (2 modes (+4.5) in the criterion): '
            'the number of modes is part of their uncertainty'),
        ('mode_count', 26.9,
            'the free fit carried the starting mode at 26.000 Hz to 26.900 Hz, where it is no mode '
            '(its damping unresolved, or not the same in both halves of the record), but the model '
            'needs it (without it the criterion rises by 15.2): it stays in the model, as a pole for '
            'what the record does not resolve there, and is not reported'),
        ('count_undecided', 19.8,
            'the free fit carried the starting mode at 19.000 Hz to 19.800 Hz, where it is no mode '
            '(its damping unresolved, or not the same in both halves of the record), but the model '
            'needs it (without it the criterion rises by 11.0): it stays in the model, as a pole for '
            'what the record does not resolve there, and is not reported; whether a mode is there, '
            'the record does not decide: compare another record of the structure, or pick it '
            "('--pick') to see what the record says of it"),
        ('mode_count', 1.0,
            '1 pole(s) of the modal model lie outside the band 1-25 Hz, are damped beyond 0.6 or are '
            "lines (damping at the fit's floor): 30 Hz (damping 0.90). They stand for what lies "
            'beyond the band or for a periodic disturbance, and are not reported as modes'),
    ]
    # the frequencies each names (the terminal's one line per code shows them)
    assert [n.freq_hz for n in notes.count_notes(_count(), KEEP, BAND, SAME_ROW)] == [
        (12.5,), (17.0,), (5.0,), (21.5,), (23.5,), (9.5,), (18.75,), (14.25,), (5.0, 12.0), (26.9,), (19.8,), (30.0,)]


@pytest.mark.parametrize("ratio", [1.0, 4.9])
def test_an_addition_the_halves_refuse_is_said_as_the_world_refuses_it(ratio):
    """Where the model is adequate the halves refuse an addition only beyond 1e-6: a change during the
    record. Where it misfits (Inglewood's ratio 4.9) the rule refuses at 1 %, which does not show a
    change: the note says the rule refused it and what it may be."""
    count = _count(adequacy=Adequacy(np.array([ratio]), 1.25))
    (said,) = [s for s in _said(notes.count_notes(count, KEEP, BAND, SAME_ROW)) if s[1] == 14.25]
    assert said[2] == ("one mode more near 14.250 Hz fits the whole record better but " + (
        "not each of its halves: a change during the record (a drifting frequency, a transient, a nonlinearity), "
        "not a mode; left out" if ratio == 1.0 else
        "its frequency and damping in the record's two halves differ beyond chance at the 1 % level, which "
        "refuses it where the model misfits the record (the count's rule): a change during the record or a mode "
        "the misfit disturbs; left out"))  # fmt: skip


def test_a_wanted_mode_says_why_it_is_not_reported_and_what_to_do():
    """A split the search did not try (no column to pick)."""
    count = _count(steps=(), removal_rise=np.array([40.0, 80.0, 60.0]), best_addition=-30.0, unconfirmed_hz=(),
                   alternatives=(), carried_away=(), stand_ins=(), unsettled_hz=(),
                   wanted=Wanted(23.5, 61.2, 12, -7.5, False))  # fmt: skip
    said = [s for s in _said(notes.count_notes(count, KEEP, BAND, SAME_ROW)) if s[1] == 23.5]
    assert said == [
        ('count_undecided', 23.5,
            'the record may hold one mode more near 23.500 Hz: adding it raises the likelihood far '
            'beyond chance (likelihood ratio 61.2 for its 12 parameters, p < 1e-06) and the mode is '
            'the same in both halves of the record, but the search, which splits only the mode '
            "nearest the residual's peak, did not try it (with it the criterion falls by 7.5), so it "
            'is not reported; the diagram holds no stable column there to pick (its ARMAX fits merge '
            'it with a neighbour); a longer record would decide'),
    ]


def test_pick_notes_say_which_pick_the_record_does_not_support_and_what_it_holds_more():
    assert _said(notes.pick_notes(_count(), KEEP)) == [
        ('pick_not_supported', 5.0,
            'the record does not support the mode picked at 5.000 Hz: without it (the other modes '
            'refitted free) the information criterion changes by +4.5, less than the 10 a needed '
            'mode raises it; treat it as tentative, or pick another column of the diagram'),
    ]
    assert _said(notes.pick_notes(_count(best_addition=12.5), np.array([False, True, False]))) == [
        ('mode_count', 21.5,
            'the record holds one mode more than the modal model behind the picks, near 21.500 Hz: '
            'adding it lowers the information criterion by 12.5'),
    ]


def test_a_model_that_keeps_no_mode_lists_its_poles_and_the_band():
    said = notes.no_mode_kept_note(_count(), pd.DataFrame({"freq_hz": [5.0, 9.0]}), BAND)
    assert _said([said]) == [
        ('count_undecided', 2.0,
            'the maximum-likelihood modal model keeps no mode in 1-25 Hz (its poles: 5 Hz (damping '
            "0.20), 12 Hz (damping 0.10), 30 Hz (damping 0.90)); the 2 mode(s) of the diagram's "
            'selection are reported, unconfirmed by it'),
    ]


def _oversampled(freq_hz, fs, settings=None):
    """The oversampling note under ``settings`` (the selection's ``NoteSettings``, as ``finish`` passes them)."""
    s = NoteSettings() if settings is None else settings
    return oversampling_note(np.array(freq_hz, float), fs, s.oversampled_fraction, s.suggested_band_factor)


def test_an_oversampled_record_is_told_the_band_and_rate_to_rerun_at():
    (said,) = _said(_oversampled([2.0, 6.3], 1000.0))
    assert said[1] == pytest.approx(6.3 / 500)
    assert said[::2] == [
        ('oversampled', 0.0126,
            'every mode lies below 1.3 % of Nyquist: rerun with --band 0:16, which resamples to 40 Hz (in Python '
            'band=(0, 16); the highest mode at 6.3 Hz of 500 Hz). The input excites far above the '
            'structure, so the rate was kept, and at this rate the poles crowd z = 1 where ARMAX models '
            'resolve them poorly; modes may be missed or biased.'),
    ][0][::2]
    assert _oversampled([2.0, 6.3], 100.0) == []  # the modes reach 13 % of Nyquist
    assert _oversampled([], 1000.0) == []


def test_modes_the_record_does_not_separate_are_named_with_their_distance():
    modes = with_intervals(pd.DataFrame({"freq_hz": [10.0, 10.5, 20.0], "freq_sd": [0.2, 0.2, 0.2], "damping": 0.05,
                                         "damping_sd": 0.001}))  # fmt: skip
    assert _said(notes.not_separated_notes(modes)) == [
        ('modes_not_separated', 10.0,
            'modes at 10.000 and 10.500 Hz are 1.8 standard deviations of their difference apart '
            '(the 95 % interval of the difference holds zero): the record does not separate them; they may be one '
            'mode'),
    ]


def test_the_edges_of_each_rule():
    """Where each rule's comparison flips: a step whose pole stayed within the clustering's reach, a
    split, an undecided removal of a mode not reported, an addition exactly decisive or nowhere,
    stand-ins on the band's edges, two alternatives and two poles outside the band."""
    model = _model((5.0, 12.0, 30.0, 40.0), (0.2, 0.1, 0.9, 0.1))
    count = _count(model=model, steps=(Step("add", 12.5, 20.0, 12.6), Step("split", 8.0, 15.0, 7.0)),
                   removal_rise=np.array([4.5, 80.0, 60.0, 70.0]), best_addition=-10.0, unconfirmed_hz=(),
                   alternatives=((4.5, _model((5.1,), (0.2,))), (6.0, _model((5.0, 12.3, 14.0), (0.2, 0.1, 0.1)))),
                   carried_away=(), wanted=(), stand_ins=((24.0, 25.0, 15.0), (2.0, 1.0, 12.0)), unsettled_hz=())
    said = _said(notes.count_notes(count, np.array([False, True, False, False]), BAND, SAME_ROW))
    assert [text for _, _, text in said[:2]] == [
        "the mode at 12.500 Hz added: the information criterion (BIC) of the maximum-likelihood modal model, "
        "every pole free, falls by 20.0",
        "the mode at 8.000 Hz split in two (its new pole settled at 7.000 Hz): the information criterion (BIC) of "
        "the maximum-likelihood modal model, every pole free, falls by 15.0",
    ]
    # 5 Hz is undecided but not reported: no note of the count's doubt; an addition at exactly -10 is decided
    assert not any("does not decide the number" in t or "rule out" in t for _, _, t in said)
    assert "in the models the record cannot tell from the chosen one (1 modes (+4.5), 3 modes (+6.0) in" in said[2][2]
    assert [(code, value) for code, value, _ in said[3:5]] == [("count_undecided", 25.0), ("count_undecided", 1.0)]
    assert said[5][1:] == (2.0, "2 pole(s) of the modal model lie outside the band 1-25 Hz, are damped beyond 0.6 "
                                "or are lines (damping at the fit's floor): 30 Hz (damping 0.90), 40 Hz (damping "
                                "0.10). They stand for what lies beyond the band or for a periodic disturbance, "
                                "and are not reported as modes")  # fmt: skip
    assert len(said) == 6
    # an addition without a place is not said; one exactly decisive is not held against the picks
    nowhere = _count(best_addition=-3.0, best_addition_hz=float("nan"))
    assert not any("rule out" in t for _, _, t in _said(notes.count_notes(nowhere, KEEP, BAND, SAME_ROW)))
    assert _said(notes.pick_notes(_count(best_addition=10.0), np.array([False, True, False]))) == []


def test_a_wanted_mode_barely_refused_says_the_criterion_rises():
    count = _count(steps=(), best_addition=-30.0, unconfirmed_hz=(), alternatives=(), carried_away=(), stand_ins=(),
                   unsettled_hz=(), wanted=Wanted(23.5, 61.2, 12, 0.5, True))  # fmt: skip
    (text,) = [t for _, v, t in _said(notes.count_notes(count, KEEP, BAND, SAME_ROW)) if v == 23.5]
    assert "but the criterion (BIC) rises by 0.5, so it is not reported" in text


def test_a_model_without_poles_says_none():
    empty = _count(model=_model((), ()), removal_rise=np.array([]))
    (said,) = _said([notes.no_mode_kept_note(empty, pd.DataFrame({"freq_hz": [5.0]}), BAND)])
    assert "(its poles: none); the 1 mode(s) of the diagram's selection" in said[2]


def test_the_oversampling_rule_at_its_edge():
    """Modes at 10 % of Nyquist are not oversampled; at 8 % they are, with the share printed to 0.1 %."""
    assert _oversampled([50.0], 1000.0) == []
    (said,) = _said(_oversampled([40.0], 1000.0))
    assert said[2].startswith(
        "every mode lies below 8.0 % of Nyquist: rerun with --band 0:100, which resamples to 250 Hz (")
    assert "the highest mode at 40 Hz of 500 Hz" in said[2]


def test_a_band_that_halves_the_rate_is_suggested():
    """With every mode below 30 % of Nyquist counting as oversampled, a mode at 8 Hz of 100 Hz
    suggests the band 0-20 Hz, which halves the rate: the smallest reduction still worth saying."""
    (said,) = _said(_oversampled([8.0], 100.0, NoteSettings(oversampled_fraction=0.3)))
    assert said[2].startswith(
        "every mode lies below 16.0 % of Nyquist: rerun with --band 0:20, which resamples to 50 Hz (")


def test_the_counts_json_holds_its_evidence_as_the_schema_says():
    """``ModeCount.to_dict``: the steps, every fitted model and every pole with its verdict, NaN as
    null, valid against the published schema's ``count``."""
    import json
    from pathlib import Path

    import jsonschema

    from armaxmodal.modes.mode_count import FittedModel

    rows = (FittedModel("start", float("nan"), 3, 120.0, 30, 160.0, True, None),
            FittedModel("add", 12.5, 4, 80.0, 40, 133.3, False, True))  # fmt: skip
    got = _count(models=rows, trials=7, effective_fraction=0.5).to_dict()
    schema = json.loads((Path(__file__).parents[2] / "schemas" / "stabilise.schema.json").read_text())
    jsonschema.validate(json.loads(json.dumps(got, allow_nan=False)), schema["properties"]["count"])
    assert (got["effective_fraction"], got["trials"]) == (0.5, 7)
    assert got["steps"] == [{"action": "add", "freq_hz": 12.5, "bic_fall": 44.25, "settled_hz": 13.5},
                            {"action": "remove", "freq_hz": 17.0, "bic_fall": 12.5, "settled_hz": None}]  # fmt: skip
    assert got["models"][0] == {"action": "start", "freq_hz": None, "n_modes": 3, "neg2_loglik": 120.0, "n_params": 30,
                                "bic": 160.0, "converged": True, "halves_agree": None}  # fmt: skip
    assert got["models"][1]["bic"] == 133.3 and got["models"][1]["halves_agree"] is True
    assert got["poles"] == [
        {"freq_hz": 5.0, "damping": 0.2, "removal_rise": 4.5, "verdict": "undecided"},
        {"freq_hz": 12.0, "damping": 0.1, "removal_rise": 80.0, "verdict": "needed"},
        {"freq_hz": 30.0, "damping": 0.9, "removal_rise": 60.0, "verdict": "not_a_mode"},
    ]


@pytest.mark.parametrize(
    ("peak_hz", "half_hz", "want"),
    [(5.0, 1.05, (5.0, 1.0 / 10.0)),  # the half-power lines 4.5-5.5 Hz: damping width / 2f
     (1.2, 1.05, (1.2, 0.7 / 2.4)),  # the half-power lines reach the band's first line, 1.0 Hz
     (2.0, 20.0, (2.0, 0.5)),  # a hump over the whole band: the damping's cap
     (5.0, 0.05, (5.0, 0.01))],  # one line: the damping's floor
)  # fmt: skip
def test_the_residual_peak_and_its_width(peak_hz, half_hz, want):
    """Where the model misses most, from a residual power shaped as a triangle of known half width
    on lines every 0.1 Hz from 1 to 10 Hz (two sensors, no smoothing)."""
    from armaxmodal.modes.mode_count import residual_peak

    f = np.round(np.arange(1.0, 10.05, 0.1), 10)
    power = np.clip(1 - np.abs(f - peak_hz) / half_hz, 0, None)
    model = SimpleNamespace(residual=np.sqrt(power / 2)[:, None] * np.ones((1, 2)) + 0j)
    got = residual_peak(model, SimpleNamespace(s=2j * np.pi * f), width_lines=1)
    assert got == pytest.approx(want, rel=1e-9)


def _facts(note) -> tuple:
    return note.code, note.channels, note.value, note.freq_hz, note.message


def test_the_count_and_screen_notes_say_their_numbers_in_their_places():
    """The notes the count's rows and the FRF screen write, each from known facts (read against
    them 2026-12-01): a pair reported as one, a mode only the modal model confirms, a pick the model
    takes away, the modes not picked, and a mode the FRF does not need, alone or beside a neighbour."""
    assert _facts(notes.reported_as_one_note((6.356, 6.395), 0.2, 0.8, 6.371, 0.0133)) == (
        "modes_not_separated", (), 6.371, (6.356, 6.395),
        "the modal model needs two poles at 6.356 and 6.395 Hz, but they are 0.2 standard deviations of their "
        "difference apart (its 95 % interval holds zero) and their shapes agree (MAC at least 0.8): the record "
        "does not separate them. "
        "Reported as one mode at 6.371 Hz (damping 0.0133, the model with one pole there), its intervals covering "
        "both: one resonance whose frequency moves during the record (a nonlinearity, a change) or two modes this "
        "record cannot resolve")  # fmt: skip
    assert _facts(notes.confirmed_where_incoherent_note(39.67, 27.4)) == (
        "mode_count", (), 39.67, (39.67,),
        "no output's H1 is coherent near 39.670 Hz, so the FRF check cannot test that mode; the maximum-likelihood "
        "modal model, fitted to the record's DFT, confirms it: without it the criterion rises by 27, and both halves "
        "of the record give it the same frequency and damping")  # fmt: skip
    assert _facts(notes.pick_moved_note(9.5, 31.2, 0.72)) == (
        "pick_not_supported", (), 9.5, (9.5,),
        "the maximum-likelihood modal model takes the mode picked at 9.500 Hz to 31.200 Hz (damping 0.72): beyond "
        "the band, damped beyond 0.6 or a line. The record does not support a mode there; it is reported from the "
        "diagram's fit, unconfirmed")  # fmt: skip
    assert _facts(notes.not_picked_note(MODEL, [0, 2])) == (
        "mode_count", (), 2.0, (5.0, 30.0),
        "2 mode(s) of the record were not picked and are not reported: 5.000 Hz (damping 0.2), 30.000 Hz (damping "
        "0.9); they stay in the modal model, so that the picked modes' values are not biased by their absence")
    assert _facts(notes.not_needed_note(8.57, 0.034, None, 0.2, 0.01, 0.15, 0.31)) == (
        "mode_not_needed", (), 8.57, (8.57,),
        "a stable pole at 8.570 Hz (damping 0.034) is left out: the measured FRF does not need it, without it no "
        "output's misfit rises by 20 % (at most +15.0 %, p = 0.31): a spurious pole of the model (noise, a "
        "nonlinearity, leakage), not a mode of the record")  # fmt: skip
    assert _facts(notes.not_needed_note(13.6, 0.3, 13.1, 0.05, 0.01, -0.004, 0.87)) == (
        "split_merged", (), 13.6, (13.1, 13.6),
        "modes at 13.100 and 13.600 Hz overlap within their half-power bands and the measured FRF does not need "
        "both: without it no output's misfit rises by 5 % (at most -0.4 %, p = 0.87) once 13.100 Hz may take the "
        "whole peak; one peak split by the model, 13.100 Hz is reported")  # fmt: skip
    # a rise past the level that chance explains is said as such, not as a rise under it
    assert notes.not_needed_note(8.57, 0.034, None, 0.05, 0.01, 0.35, 0.31).message == (
        "a stable pole at 8.570 Hz (damping 0.034) is left out: the measured FRF does not need it, without it an "
        "output's misfit rises by +35.0 %, but not significantly (p = 0.31, above 0.01): a spurious pole of the "
        "model (noise, a nonlinearity, leakage), not a mode of the record")  # fmt: skip
    at_the_level = notes.not_needed_note(8.57, 0.03, None, 0.05, 0.01, 0.05, 0.2)
    assert "rises by +5.0 %, but not significantly" in at_the_level.message


def test_a_left_out_start_beside_a_coherent_peak_is_said_undecided_with_every_peak_near_it():
    """Two unexplained peaks near where a carried-away start began and went, one far from both, and
    a second start with no peak near: one note, naming both near peaks."""
    from armaxmodal.quality_warnings import QualityWarning

    peaks = [QualityWarning("unexplained_peak", (s,), "a peak", f, (f,)) for s, f in
             (("head", 8.05), ("legs", 9.52), ("legs", 14.0))]  # fmt: skip
    (note,) = notes.dropped_where_peaks_remain(SimpleNamespace(carried_away=((8.0, 9.5), (20.0, 21.0))), peaks, 0.05)
    assert _facts(note) == (
        "count_undecided", (), 8.0, (8.0, 8.05, 9.52),
        "the starting mode at 8.000 Hz was left out (the free fit took it to 9.500 Hz, where it is no mode), but the "
        "measured FRF keeps a coherent peak no mode explains at 8.05, 9.52 Hz: the record does not decide whether a "
        "mode is there; compare another record of the structure, or pick it ('--pick') to see what the record says "
        "of it")  # fmt: skip
