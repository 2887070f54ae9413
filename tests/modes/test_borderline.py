"""A pole beyond the band (or damped beyond ``MAX_DAMPING``) by its estimate but not by its 95 %
interval: the record does not decide whether the band holds a mode there, so the count calls it
``borderline``, does not report it, and says so in a ``count_undecided`` note (which makes the
verdict ``uncertain``). Unseen bodies with feet lost a heavily damped top mode this way under
``good``: 26.4 Hz estimated at 28.07 Hz in a band ending at 28.06 Hz. A needed pole beyond the
band by its intervals too, its resonance reaching in, is a mode beyond the band: ``beyond_band``,
named in a ``mode_beyond_band`` note (a body's 27.7 Hz mode under a ride to 24 Hz)."""

from __future__ import annotations

import json
from dataclasses import replace
from functools import partial
from pathlib import Path
from types import SimpleNamespace

import jsonschema
import numpy as np
import pytest

import armaxmodal as am
from armaxmodal.estimate import dft_model
from armaxmodal.estimate.dft_model import DftLines
from armaxmodal.modes.mode_count import ModeCount
from armaxmodal.modes.notes import count_notes
from armaxmodal.modes.poles import beyond_band, borderline
from armaxmodal.modes.settings import DEFAULTS, ClusterSettings
from armaxmodal.stats import MAX_DAMPING, Z95

# the fitter under the selection's default damping bounds and tolerance
fit_modal_model = partial(dft_model.fit_modal_model, settings=DEFAULTS.dft)

BAND = (1.0, 25.0)
FLOOR = 2 * DEFAULTS.dft.min_damping  # a pole within twice the fit's floor is a line
NYQUIST = 50.0  # the stand-in models' bound on a pole's frequency (Hz)


def _model(freq, damping, freq_sd, damping_sd):
    return SimpleNamespace(freq_hz=np.array(freq, float), damping=np.array(damping, float),
                           freq_sd=np.array(freq_sd, float), damping_sd=np.array(damping_sd, float),
                           n_modes=len(freq), nyquist_hz=NYQUIST, at_bound=None,
                           damping_floor=DEFAULTS.dft.min_damping)  # fmt: skip


@pytest.mark.parametrize(
    ("freq", "damping", "freq_sd", "damping_sd", "want"),
    [(26.0, 0.3, 0.6, 0.01, True),  # beyond the top, its interval reaching back in (24.8 Hz)
     (26.0, 0.3, 0.4, 0.01, False),  # beyond the top, its interval too (25.2 Hz): decided out
     (25.0 + Z95 * 0.5 - 1e-9, 0.3, 0.5, 0.01, True),  # the interval's end just inside the band's edge
     (25.0 + Z95 * 0.5 + 1e-9, 0.3, 0.5, 0.01, False),
     (0.8, 0.3, 0.2, 0.01, True),  # below the band's bottom, reaching into it
     (0.5, 0.3, 0.2, 0.01, False),
     (12.0, 0.7, 0.5, 0.06, True),  # in the band, damped beyond 0.6 but not by its interval
     (12.0, 0.7, 0.5, 0.04, False),
     (12.0, MAX_DAMPING + Z95 * 0.05 - 1e-9, 0.5, 0.05, True),  # the damping interval's end just under the bound
     (12.0, MAX_DAMPING + Z95 * 0.05 + 1e-9, 0.5, 0.05, False),
     (26.0, 0.7, 0.6, 0.06, True),  # beyond both, reaching back into both
     (26.0, 0.7, 0.6, 0.04, False),  # reaching into the band only: still over-damped
     (26.0, 0.3, np.nan, 0.01, True),  # an interval not known decides nothing
     (12.0, 0.3, 0.5, 0.01, False),  # a mode of the band: reported, not borderline
     (26.0, FLOOR, 5.0, 1.0, False)],  # a line at the fit's floor stays a line
)  # fmt: skip
def test_a_pole_is_borderline_when_its_interval_reaches_what_its_estimate_does_not(freq, damping, freq_sd, damping_sd,
                                                                                 want):  # fmt: skip
    got = borderline(_model([5.0, freq], [0.2, damping], [0.01, freq_sd], [0.01, damping_sd]), BAND)
    assert got.tolist() == [False, want]


def test_a_pole_held_at_a_bound_of_the_fit_is_not_borderline():
    """Its Wald interval means nothing at a bound: the same pole, reaching into the band by it, is
    borderline off the bound and not at it (``at_bound``, the solver's active set)."""
    model = _model([5.0, 0.8], [0.2, 0.95], [0.01, 0.2], [0.01, 0.6])
    assert borderline(model, BAND).tolist() == [False, True]
    model.at_bound = np.array([False, True])
    assert borderline(model, BAND).tolist() == [False, False]


def test_the_fit_marks_the_poles_it_holds_at_a_bound():
    """A drift (a slow ramp on every sensor) takes a pole at half the lowest line, damping at its
    bound (the snapshot's drift-damaged copy had two there, their intervals "reaching" -0.01 to
    0.02 Hz, each said ``count_undecided``). The solver's active set marks it, and only it, in the
    model's frequency order (the start lists it last)."""
    body = am.supine_human()
    exact = body.modes()
    ride = am.simulate_recording(body, am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03, seed=2)
    ramp = 0.05 * ride.time[:, None] * np.ones(len(ride.sensors))
    drifting = am.Recording(ride.fs, ride.base, ride.response + ramp, ride.sensors, ride.input_name)
    data = DftLines.from_recording(drifting, (1 / 60, 28.0))
    model = fit_modal_model(data, np.r_[exact.freq_hz, 0.01], np.r_[exact.damping, 0.9], hold="zoh")
    assert model.at_bound.tolist() == [True, False, False, False, False]
    assert model.freq_hz[0] == pytest.approx(data.band_hz[0] / 2) and model.damping[0] == pytest.approx(0.95)
    np.testing.assert_allclose(model.freq_hz[1:], exact.freq_hz, rtol=0.02)


def _count(freq, damping, freq_sd, damping_sd):
    model = _model(freq, damping, freq_sd, damping_sd)
    return ModeCount(model, model, (), np.full(len(freq), 60.0), -40.0, 12.0, 1.0, band_hz=BAND)


def test_the_count_calls_it_borderline_reports_it_not_and_says_so():
    count = _count([5.0, 26.0, 40.0], [0.2, 0.45, 0.3], [0.01, 0.8, 0.5], [0.01, 0.05, 0.01])
    assert list(count.verdicts()) == ["needed", "borderline", "not_a_mode"]
    assert list(count.reported()) == [True, False, False]
    # another band: 26 Hz in it, and 40 Hz a mode above it (its resonance, 28-52 Hz, reaching in)
    assert list(count.verdicts((1.0, 30.0))) == ["needed", "needed", "beyond_band"]
    schema = json.loads((Path(__file__).parents[2] / "schemas" / "stabilise.schema.json").read_text())
    got = count.to_dict()
    jsonschema.validate(json.loads(json.dumps(got, allow_nan=False)), schema["properties"]["count"])
    assert [p["verdict"] for p in got["poles"]] == ["needed", "borderline", "not_a_mode"]
    notes = count_notes(count, count.reported(), BAND, ClusterSettings().same_row_freq)
    undecided = [n for n in notes if n.code == "count_undecided"]
    assert [n.value for n in undecided] == [26.0]
    lo, hi = 26.0 - Z95 * 0.8, 26.0 + Z95 * 0.8
    assert f"({lo:.4g}-{hi:.4g} Hz" in undecided[0].message and "beyond the band 1-25 Hz" in undecided[0].message
    assert "into the band" in undecided[0].message and f"below {MAX_DAMPING:g}" not in undecided[0].message
    # the note of the poles that stand for what lies beyond the band names only the decided one
    (beyond,) = [n for n in notes if n.code == "mode_count" and "outside the band" in n.message]
    assert "40 Hz" in beyond.message and "26 Hz" not in beyond.message and beyond.value == 1.0
    assert (undecided[0].freq_hz, beyond.freq_hz) == ((26.0,), (40.0,))  # what the terminal's line names
    # the same pole decided out (a narrow interval): no doubt; a mode above the band, named as such
    decided = replace(count, model=_model([5.0, 26.0, 40.0], [0.2, 0.45, 0.3], [0.01, 0.2, 0.5], [0.01, 0.05, 0.01]))
    assert list(decided.verdicts()) == ["needed", "beyond_band", "not_a_mode"]
    said = count_notes(decided, decided.reported(), BAND, 0.05)
    assert "count_undecided" not in [n.code for n in said]
    assert [n.freq_hz for n in said if n.code == "mode_beyond_band"] == [(26.0,)]
    jsonschema.validate(json.loads(json.dumps(decided.to_dict(), allow_nan=False)), schema["properties"]["count"])


def test_an_over_damped_borderline_pole_is_said_as_such():
    count = _count([5.0, 12.0], [0.2, 0.68], [0.01, 0.5], [0.01, 0.06])
    (note,) = [n for n in count_notes(count, count.reported(), BAND, 0.05) if n.code == "count_undecided"]
    lo, hi = 0.68 - Z95 * 0.06, 0.68 + Z95 * 0.06
    assert (note.channels, note.value, note.freq_hz) == ((), 12.0, (12.0,))
    assert note.message == (
        f"the modal model's pole at 12.000 Hz (damping 0.68) lies damped beyond {MAX_DAMPING:g}, so it is not reported "
        f"as a mode, but its 95 % interval ({12 - Z95 * 0.5:.4g}-{12 + Z95 * 0.5:.4g} Hz, damping {lo:.2f}-{hi:.2f}) "
        f"reaches below {MAX_DAMPING:g}: the record does not decide whether the band holds one mode more there (a "
        "heavily damped mode near the band's edge is estimated so); excite and fit a band reaching past it to decide")


def test_a_pole_past_both_edges_is_said_past_both():
    count = _count([5.0, 26.0], [0.2, 0.65], [0.01, 0.8], [0.01, 0.05])
    (note,) = [n for n in count_notes(count, count.reported(), BAND, 0.05) if n.code == "count_undecided"]
    assert f"lies beyond the band 1-25 Hz and damped beyond {MAX_DAMPING:g}, so" in note.message
    assert f"reaches into the band and below {MAX_DAMPING:g}: the" in note.message


@pytest.fixture(scope="module")
def supine_fits():
    """The supine body's modes (exact 5.83, 8.31, 13.50, 16.25 Hz, damping 0.26-0.35) fitted on a
    60 s ride over bands ending at 14.5, 16.3 and 17.0 Hz."""
    body = am.supine_human()
    exact = body.modes()
    ride = am.simulate_recording(body, am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03, seed=2)
    fits = {}
    for top in (14.5, 16.3, 17.0):
        band = (0.5, top)
        model = fit_modal_model(DftLines.from_recording(ride, band), exact.freq_hz, exact.damping, hold="zoh")
        fits[top] = ModeCount(model, model, (), np.full(4, 60.0), -40.0, np.nan, 1.0, band_hz=band)
    return fits


def test_a_damped_mode_just_inside_the_top_is_not_dropped_in_silence(supine_fits):
    """Fitted on lines up to 16.3 Hz, the 16.25 Hz mode (damping 0.27) comes out at 16.4 Hz, beyond
    the band, its interval about 15.9-16.9 Hz: it was a pole 'beyond the band', unreported and
    unsaid, under 'good'. Now it is borderline and a note makes the verdict uncertain."""
    count = supine_fits[16.3]
    assert count.model.freq_hz[3] > 16.3 and count.verdicts()[3] == "borderline"
    notes = count_notes(count, count.reported(), count.band_hz, 0.05)
    assert [n.code for n in notes].count("count_undecided") == 1


@pytest.mark.parametrize(("top", "verdict"), [(14.5, "beyond_band"), (17.0, "needed")])
def test_a_mode_well_past_the_top_or_well_inside_it_is_decided(supine_fits, top, verdict):
    """Lines up to 14.5 Hz put the 16.25 Hz mode's interval wholly beyond the band (about 14.9-18.0
    Hz), its resonance reaching into it: a mode above the band, named; lines up to 17.0 Hz put its
    estimate inside."""
    count = supine_fits[top]
    assert count.verdicts()[3] == verdict
    beyond = [n for n in count_notes(count, count.reported(), count.band_hz, 0.05) if n.code == "mode_beyond_band"]
    assert len(beyond) == (top == 14.5)
    if beyond:
        (lo, hi), exact = beyond[0].message.split("95 % interval ")[1].split(" Hz")[0].split("-"), 16.25
        assert float(lo) > top and float(lo) < exact < float(hi)  # the exact mode inside what is named


@pytest.mark.parametrize(
    ("freq", "damping", "freq_sd", "damping_sd", "want"),
    [(27.0, 0.4, 0.5, 0.02, True),  # wholly above the band, its resonance reaching into it
     (27.0, 0.4, 1.1, 0.02, False),  # its interval reaching back into the band: borderline, not decided
     (25.0 + Z95 * 0.5 + 1e-9, 0.4, 0.5, 0.02, True),  # the interval's end just past the band's edge
     (25.0 + Z95 * 0.5 - 1e-9, 0.4, 0.5, 0.02, False),
     (25.0 / 0.7 - 1e-6, 0.3, 0.5, 0.02, True),  # the half-power band's lower end just inside the band
     (25.0 / 0.7 + 1e-6, 0.3, 0.5, 0.02, False),  # just outside: a pole for all that lies up there
     (40.0, 0.3, 0.5, 0.02, False),
     (0.9, 0.3, 0.02, 0.02, True),  # below the band, its resonance reaching up into it
     (0.6, 0.3, 0.05, 0.02, False),  # below, not reaching (0.78 Hz)
     (0.9, 0.3, 0.1, 0.02, False),  # below, its interval reaching back into the band: borderline
     (27.0, 0.4, 0.5, 0.25, False),  # its damping not resolved (the interval crosses zero)
     (27.0, 0.55, 0.5, 0.06, True),  # damped at most MAX_DAMPING, as a mode of the band (its interval past it)
     (27.0, MAX_DAMPING + 0.01, 0.5, 0.01, False),  # damped beyond it
     (27.0, 0.4, np.nan, 0.02, False),  # an interval not known decides nothing
     (48.0, 0.55, 0.5, 0.02, True),
     (NYQUIST, 0.55, 0.5, 0.02, False),  # held at the fit's bound: its interval means nothing
     (12.0, 0.3, 0.5, 0.01, False),  # a mode of the band
     (27.0, FLOOR, 0.5, 1e-6, False)],  # a line
)  # fmt: skip
def test_a_pole_is_a_mode_beyond_the_band_when_its_intervals_say_so(freq, damping, freq_sd, damping_sd, want):
    got = beyond_band(_model([5.0, freq], [0.2, damping], [0.01, freq_sd], [0.01, damping_sd]), BAND)
    assert got.tolist() == [False, want]


def test_only_a_needed_pole_beyond_the_band_is_named_and_the_note_says_where_to_reach():
    count = _count([5.0, 27.0, 0.9], [0.2, 0.4, 0.3], [0.01, 0.5, 0.02], [0.01, 0.02, 0.02])
    assert list(count.verdicts()) == ["needed", "beyond_band", "beyond_band"]
    assert list(count.reported()) == [True, False, False]
    notes = count_notes(count, count.reported(), BAND, 0.05)
    above, below = [n for n in notes if n.code == "mode_beyond_band"]
    df, dx = Z95 * 0.5, Z95 * 0.02
    assert above.message == (
        f"the record holds a mode above the band 1-25 Hz: the modal model needs a pole at 27.000 Hz (95 % interval "
        f"{27 - df:.4g}-{27 + df:.4g} Hz), damping 0.400 ({0.4 - dx:.3f}-{0.4 + dx:.3f}). It is not reported, as it "
        "lies outside the band (the input's excited band, or --band within it); to report it, excite the structure "
        f"and fit a band reaching past {27 + df:.3g} Hz")
    assert below.message.endswith(f"fit a band reaching below {0.9 - Z95 * 0.02:.3g} Hz") and below.freq_hz == (0.9,)
    assert (above.channels, above.value, above.freq_hz) == ((), 27.0, (27.0,))
    assert not [n for n in notes if n.code == "mode_count" and "outside the band" in n.message]  # said once
    weak = replace(count, removal_rise=np.array([60.0, 5.0, 5.0]))  # not needed: what lies up there, unnamed
    assert list(weak.verdicts()) == ["needed", "not_a_mode", "not_a_mode"]
    assert "mode_beyond_band" not in [n.code for n in count_notes(weak, weak.reported(), BAND, 0.05)]


def test_a_drifting_record_is_uncertain_for_its_drift_alone(tmp_path):
    """The snapshot's drift-damaged fixture (every sensor ramping 0.05 m/s^2 a second): the count
    keeps two poles at half the lowest line that stand for the drift, one with its damping just off
    its bound (only its frequency held). They are no modes of the band and not borderline: the
    verdict is ``uncertain`` for the drift, with no ``count_undecided`` note about them."""
    import pandas as pd

    frame = pd.read_csv(Path(__file__).parents[2] / "fixtures" / "supine_random.csv", comment="#")
    outs = ["head", "chest", "pelvis", "legs"]
    frame[outs] += 0.05 * np.arange(len(frame))[:, None] / 60.0
    frame.to_csv(tmp_path / "drift.csv", index=False)
    selection = am.select_modes(am.stabilisation_diagram(am.read_recording(tmp_path / "drift.csv")))
    codes = {w.code for w in selection.warnings}
    assert selection.uncertain_because == ["drift"] and "count_undecided" not in codes
    low = selection.count.model.freq_hz < selection.count.band_hz[0]
    assert low.sum() == 2 and set(selection.count.verdicts()[low]) == {"not_a_mode"}
    np.testing.assert_allclose(selection.modes.freq_hz, am.supine_human().modes().freq_hz, rtol=0.02)
