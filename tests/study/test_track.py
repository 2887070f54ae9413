"""``track``: modes followed across events of one structure against the exact law they were
simulated by, a planted outlier event flagged and no other, the trend's scatter against known
truth, the matching rule's gates, and the command's files written whole."""

import json
import math

import numpy as np
import pandas as pd
import pytest

import armaxmodal as am
from armaxmodal.cli import main
from armaxmodal.exceptions import DataError
from armaxmodal.study import TrackSettings, fit_trend, match_tracks, track_modes
from tests.cli.test_schemas import _validator

#: the simulated structure softens by this fraction of its frequencies per tenfold input
SOFTENING = 0.04
#: the planted outlier: its frequencies this factor below the law
OUTLIER = 0.93
RMS = (0.1, 0.2, 0.5, 0.7, 1.0, 2.0, 5.0)
OUTLIER_RMS = 0.7
#: a slope within this many of its own standard deviations of the law's
SLOPE_SDS = 3.0


def law(rms: float) -> float:
    """The frequency factor of an event driven at ``rms`` (1 at 0.1)."""
    return (1 - SOFTENING * math.log10(rms / 0.1)) * (OUTLIER if rms == OUTLIER_RMS else 1.0)


@pytest.fixture(scope="module")
def events(tmp_path_factory):
    """Seven rides of the supine body, its K scaled by law**2 and C by law (the damping ratios
    unchanged), listed in a manifest with dates."""
    folder = tmp_path_factory.mktemp("events")
    body = am.supine_human()
    rows = []
    for k, rms in enumerate(RMS):
        s = law(rms)
        softened = am.Structure(body.M, body.C * s, body.K * s**2, body.names)
        base = am.random_vibration(60.0, 60.0, rms=rms, seed=10 + k)
        ride = am.simulate_recording(softened, base, 60.0, noise=0.03, seed=20 + k)
        am.write_recording_csv(ride, folder / f"event{k}.csv")
        rows.append({"file": f"event{k}.csv", "date": f"2026-{k + 1:02d}-15", "site": "lab"})
    pd.DataFrame(rows).to_csv(folder / "manifest.csv", index=False)
    return folder


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("cache")


@pytest.fixture(scope="module")
def followed(events, cache):
    return track_modes(events / "manifest.csv", cache, jobs=2)


def test_each_mode_is_one_track_whose_slope_is_the_law(followed):
    exact = am.supine_human().modes().freq_hz
    trends = followed.trends.set_index("mode")
    assert list(trends.index) == [1, 2, 3, 4]
    assert (trends.events == len(RMS)).all()
    for mode, f0 in enumerate(exact, start=1):
        rows = followed.table[followed.table["mode"] == mode]
        # each event's mode is its own structure's (exact f0 * law), whichever track it joined
        rms = [RMS[int(name[5])] for name in rows.file]
        assert np.allclose(rows.freq_hz, [f0 * law(r) for r in rms], rtol=0.02)
        slope = -SOFTENING * f0  # Hz per tenfold input, in the RMS as in the peak
        assert abs(trends.slope_hz_per_decade[mode] - slope) < SLOPE_SDS * trends.slope_sd[mode]
    # fitted over the events not flagged, which agree within their intervals: no scatter to speak of
    # (through the planted event too, it would read 0.16-0.40 Hz)
    assert (trends.tau_hz < 0.02).all(), trends.tau_hz


def test_the_planted_outlier_and_no_other_event_is_flagged(followed):
    flagged = followed.table[followed.table.flagged]
    assert set(flagged.file) == {f"event{RMS.index(OUTLIER_RMS)}.csv"}
    assert sorted(flagged["mode"]) == [1, 2, 3, 4]
    assert (flagged.freq_hz < flagged.trend_hz).all()
    assert any("event3.csv" in note and "departs beyond its interval" in note for note in followed.notes)


def test_dates_and_peaks_are_the_events(followed, events):
    ev = followed.events.set_index("file")
    assert ev.date["event0.csv"] == pd.Timestamp("2026-01-15")
    ride = am.read_recording(events / "event4.csv")
    assert ev.peak_input["event4.csv"] == pytest.approx(np.abs(ride.base - ride.base.mean()).max())


def test_matching_follows_modes_listed_in_any_order_and_missing_ones():
    bend, twist, sway = np.array([1.0, 1.0, 1.0]), np.array([1.0, 0.0, -1.0]), np.array([1.0, -1.0, 1.0])
    events = [
        [(4.0, bend), (6.0, twist), (9.0, sway)],
        [(5.5, twist), (3.7, bend)],  # listed out of order, the 9 Hz mode not seen
        [(8.1, sway), (3.4, bend), (5.1, twist)],
    ]
    labels = match_tracks(events, TrackSettings())
    assert [[t for t, _ in e] for e in labels] == [[0, 1, 2], [1, 0], [2, 0, 1]]
    assert labels[1][0][1] == pytest.approx(1.0) and math.isnan(labels[0][0][1])


def test_matching_gates_by_frequency_ratio_and_by_mac_when_asked():
    bend, twist = np.array([1.0, 1.0]), np.array([1.0, -1.0])
    beyond = match_tracks([[(4.0, bend)], [(4.0 * 1.4, bend)]], TrackSettings(freq_ratio=1.35))
    assert [e[0][0] for e in beyond] == [0, 1]
    within = match_tracks([[(4.0, bend)], [(4.0 * 1.3, bend)]], TrackSettings(freq_ratio=1.35))
    assert [e[0][0] for e in within] == [0, 0]
    # a shape orthogonal to the track's joins it by default (the shape breaks ties only) ...
    assert [e[0][0] for e in match_tracks([[(4.0, bend)], [(4.1, twist)]], TrackSettings())] == [0, 0]
    # ... not under a MAC gate
    assert [e[0][0] for e in match_tracks([[(4.0, bend)], [(4.1, twist)]], TrackSettings(min_mac=0.8))] == [0, 1]
    # of two modes near one track, the one of like shape takes it
    labels = match_tracks([[(4.0, bend)], [(4.05, twist), (4.2, bend)]], TrackSettings())
    assert [t for t, _ in labels[1]] == [1, 0]


def test_trend_scatter_is_the_scatter_planted_between_events():
    rng = np.random.default_rng(5)
    x = rng.uniform(-2, 0, 400)
    sd = rng.uniform(0.005, 0.02, 400)
    tau = 0.03
    y = 4.0 - 0.5 * x + rng.normal(0, np.sqrt(sd**2 + tau**2))
    trend = fit_trend(x, y, sd)
    assert math.sqrt(trend.tau2) == pytest.approx(tau, rel=0.1)
    assert trend.coef == pytest.approx([4.0, -0.5], abs=3 * np.sqrt(np.diag(trend.cov)).max())
    # Paule-Mandel's defining equation: the weighted residual sum of squares is its degrees of freedom
    w = 1 / (sd**2 + trend.tau2)
    assert np.sum(w * (y - (trend.coef[0] + trend.coef[1] * x)) ** 2) == pytest.approx(400 - 2, rel=1e-6)


def test_no_scatter_is_invented_where_events_agree_within_their_intervals():
    x = np.linspace(-2, 0, 10)
    trend = fit_trend(x, 4.0 - 0.5 * x, np.full(10, 0.01))
    assert trend.tau2 == 0.0 and trend.coef == pytest.approx([4.0, -0.5])
    constant = fit_trend(x, np.full(10, 4.0), np.full(10, 0.01), sloped=False)
    assert constant.coef.tolist() == pytest.approx([4.0]) and constant.at(-1.0)[0] == pytest.approx(4.0)


def test_a_bad_date_is_refused_before_any_fit(events, tmp_path):
    manifest = tmp_path / "manifest.csv"
    pd.DataFrame({"file": [str(events / "event0.csv")], "date": ["the 3rd of May"]}).to_csv(manifest, index=False)
    with pytest.raises(DataError, match="ISO 8601"):
        track_modes(manifest, tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_settings_out_of_range_are_refused():
    with pytest.raises(DataError, match="freq_ratio"):
        TrackSettings(freq_ratio=0.9)
    with pytest.raises(DataError, match="level"):
        TrackSettings(level=1.5)


def test_the_command_writes_its_files_from_the_cache(events, followed, cache, tmp_path, capsys):
    out = tmp_path / "track"
    # the fixture's per-event results, reused: the command must give the same tracks from them
    (out / ".cache").mkdir(parents=True)
    for cached in (cache / ".cache").glob("*.json"):
        (out / ".cache" / cached.name).write_bytes(cached.read_bytes())
    code = main(
        ["track", str(events / "manifest.csv"), "--out", str(out), "--jobs", "1", "--quiet", "--input-unit", "m/s2"]
    )
    assert code == 0
    printed = capsys.readouterr().out
    assert "7 events, 4 modes followed, 4 departures flagged" in printed
    names = {p.name for p in out.iterdir()}
    assert {"track.csv", "trends.csv", "events.csv", "track.json", "track.png", "track.html"} <= names
    data = json.loads((out / "track.json").read_text(), parse_constant=lambda c: pytest.fail(f"bare {c}"))
    assert not list(_validator("track").iter_errors(data))
    assert data["settings"]["input_unit"] == "m/s2" and data["events"][0]["date"].startswith("2026-")
    assert sum(row["flagged"] for row in data["modes"]) == 4
    assert "mode 1 on event3.csv" in (out / "track.html").read_text()


def test_events_are_matched_from_the_weakest_shaking_not_in_the_manifests_order():
    """A mode that softens 40 % over five events, listed by date in another order than their
    shaking: matched weakest first, each step is within the frequency ratio and the mode is one
    track; matched in the listed order, its first and second events are 1.67 apart and it splits."""
    from types import SimpleNamespace

    from armaxmodal.study.track import follow

    def event(k: int, peak: float, freq: float) -> dict:
        shape = {"head": {"mag": 1.0, "phase_deg": 0.0}}
        mode = {"freq_hz": freq, "freq_ci95": [freq - 0.05, freq + 0.05], "damping": 0.05,
                "damping_ci95": [0.04, 0.06], "shape": shape}  # fmt: skip
        return {"file": f"e{k}.csv", "labels": {"date": f"2026-0{k + 1}-01"}, "peak_input": peak,
                "quality": "good", "modes": [mode]}  # fmt: skip

    listed = [(0.1, 4.0), (10.0, 2.4), (0.3, 3.6), (3.0, 2.8), (1.0, 3.2)]  # by date, not by shaking
    study = SimpleNamespace(recordings=[event(k, p, f) for k, (p, f) in enumerate(listed)], sensors=("head",),
                            notes=[], tables=SimpleNamespace(notes=[]), failures=[])  # fmt: skip
    followed = follow(study, TrackSettings())
    assert followed.table["mode"].tolist() == [1] * 5
    assert followed.table.freq_hz.tolist() == [4.0, 3.6, 3.2, 2.8, 2.4]  # in the order of the shaking


def test_a_structure_whose_every_event_is_poor_writes_its_files_and_says_why(tmp_path):
    from types import SimpleNamespace

    from armaxmodal.study import write_track
    from armaxmodal.study.track import follow

    poor = [{"file": f"e{k}.csv", "labels": {}, "peak_input": 0.1 * (k + 1), "quality": "poor", "modes": []}
            for k in range(2)]  # fmt: skip
    study = SimpleNamespace(recordings=poor, sensors=("deck",), notes=[], tables=SimpleNamespace(notes=[]),
                            failures=[], to_dict=lambda: {"settings": {}})  # fmt: skip
    followed = follow(study, TrackSettings())
    assert followed.table.empty and len(followed.events) == 2
    assert [note.split(":")[0] for note in followed.notes] == ["e0.csv", "e1.csv"]
    assert {p.name for p in write_track(followed, tmp_path)} >= {"track.csv", "track.png", "track.html"}


def test_a_resonance_the_input_does_not_drive_is_said_and_drawn_not_tracked():
    """Painter Street's two weakest events as the study leaves them: poor, with an
    ``undriven_resonance`` note each (4.34 and 4.15 Hz): each is in the events table and the notes,
    and drawn as a hollow diamond at its peak input, though no mode of it is tracked."""
    from types import SimpleNamespace

    from armaxmodal.study import plot_track
    from armaxmodal.study.track import follow, undriven_hz

    def event(name, date, peak, hz):
        notes = [{"code": "undriven_resonance", "value": hz}, {"code": "resampled", "value": 2.0}]
        return {"file": name, "labels": {"date": date}, "peak_input": peak, "quality": "poor", "modes": [],
                "warnings": notes}  # fmt: skip

    recordings = [event("a.csv", "2021-12-20", 0.0085, 4.34), event("b.csv", "2023-08-17", 0.015, 4.15)]
    assert undriven_hz(recordings[0]) == [4.34]
    study = SimpleNamespace(recordings=recordings, sensors=("deck",), notes=[], tables=SimpleNamespace(notes=[]))
    track = follow(study, TrackSettings())
    assert list(track.events.undriven_hz) == ["4.340", "4.150"] and track.table.empty
    assert sum("named at 4.340 Hz (undriven_resonance)" in note for note in track.notes) == 1
    fig = plot_track(track)
    (diamonds,) = [c for c in fig.axes[0].collections if c.get_label().startswith("resonance the input")]
    assert np.allclose(diamonds.get_offsets(), [[0.0085, 4.34], [0.015, 4.15]])
