"""Chapter 5: relative transmissibility, Morlet scalogram and wavelet coherence against known
signals, and the lumping verdict against how each subject was built."""

import numpy as np
import pytest

import armaxmodal as am
from armaxmodal.exceptions import DataError
from armaxmodal.lumping import lump_check, relative_transmissibility, scalogram, wavelet_coherence
from armaxmodal.recording import Recording
from armaxmodal.study.synthetic import subject_structure
from armaxmodal.systems.simulation import add_noise, random_vibration, simulate

FS = 60.0


def test_scalogram_peaks_at_the_sine_frequency_and_its_cone_grows_to_the_edges():
    t = np.arange(0, 60, 1 / FS)
    for f0 in (3.0, 7.5, 14.0):
        sc = scalogram(np.sin(2 * np.pi * f0 * t), FS, (0.5, 28.0))
        peak = sc.freq_hz[np.argmax(sc.power[:, t.size // 2])]
        assert abs(np.log2(peak / f0)) <= 1 / 12  # within one voice of 12 per octave
    # edge effects reach higher frequencies near the ends of the record
    assert sc.coi_hz[0] > sc.coi_hz[t.size // 4] > sc.coi_hz[t.size // 2]
    assert not sc.inside_coi()[:, 0].any() and sc.inside_coi()[:, t.size // 2].any()


def test_wavelet_coherence_recovers_a_known_lag_and_its_red_noise_level_holds_5_percent():
    rng = np.random.default_rng(3)
    t = np.arange(0, 120, 1 / FS)
    lag = np.deg2rad(40.0)
    x = np.sin(2 * np.pi * 6 * t) + 0.3 * rng.standard_normal(t.size)
    y = np.sin(2 * np.pi * 6 * t - lag) + 0.3 * rng.standard_normal(t.size)
    w = wavelet_coherence(x, y, FS, (1.0, 20.0), mc=30)
    k = np.argmin(np.abs(w.freq_hz - 6.0))
    mid = slice(t.size // 4, 3 * t.size // 4)
    assert np.median(w.r2[k, mid]) > 0.9
    assert np.degrees(np.median(w.phase_rad[k, mid])) == pytest.approx(40.0, abs=4.0)
    # y ahead instead of behind: the sign flips
    w_ahead = wavelet_coherence(y, x, FS, (1.0, 20.0), significance=None)
    assert np.degrees(np.median(w_ahead.phase_rad[k, mid])) == pytest.approx(-40.0, abs=4.0)
    # two independent noises exceed the 95 % level about 5 % of the time, inside the cone
    a, b = rng.standard_normal((2, t.size))
    wn = wavelet_coherence(a, b, FS, (1.0, 20.0), mc=30, seed=1)
    inside = wn.freq_hz[:, None] >= wn.coi_hz[None, :]
    rate = np.mean((wn.r2 > wn.significance[:, None])[inside])
    assert 0.02 < rate < 0.10


def _feet_ride(separate: bool, seed: int = 5, noise: float = 0.03):
    rng = np.random.default_rng(seed)
    structure = subject_structure(rng, 77.0, separate_feet=separate)
    u = random_vibration(FS, 120.0, (0.5, 28.0), seed=seed)
    y = simulate(structure, u, FS, hold="bandlimited")
    names = list(structure.names)
    if not separate:
        y, names = np.column_stack([y, y[:, 3]]), names + ["feet"]
    return structure, Recording(FS, u, add_noise(y, noise, rng), names)


def test_relative_transmissibility_matches_the_exact_ratio_of_the_structure():
    structure, rec = _feet_ride(separate=True, noise=0.01)
    f, t, _, measurable = relative_transmissibility(rec, "legs", "feet")
    exact = structure.epfrf(f[1:])  # relative acceleration over base = -EPFRF (zero at 0 Hz)
    f, t, measurable = f[1:], t[1:], measurable[1:]
    t_exact = exact[:, 4] / exact[:, 3]
    use = (measurable > 0.9) & (f > 1.0) & (f < 25.0)
    assert use.sum() > 100
    err = np.abs(t[use] / t_exact[use] - 1)
    assert np.median(err) < 0.03 and np.max(err) < 0.15


@pytest.mark.parametrize("separate, verdict", [(False, "lump"), (True, "separate")])
def test_lump_verdict_follows_how_the_feet_were_built(separate, verdict):
    _, rec = _feet_ride(separate)
    check = lump_check(rec, "legs", "feet")
    assert check.verdict == verdict, check.message
    d = check.to_dict()
    if separate:
        # the separate feet (own mode at 9 Hz on fixed legs) part from the legs well below it
        assert d["first_disagreement_hz"] < 9.0 and d["gain_range"][1] > 1.5
    else:
        assert 0.85 < d["gain_range"][0] and d["gain_range"][1] < 1.15 and d["max_abs_phase_deg"] < 10
        assert d["wavelet"]["median_r2"] > 0.9 and abs(d["wavelet"]["mean_phase_deg"]) < 5


def test_lump_check_refuses_missing_or_identical_segments():
    _, rec = _feet_ride(False)
    with pytest.raises(DataError, match="no sensor 'toes'"):
        lump_check(rec, "legs", "toes")
    with pytest.raises(DataError, match="itself"):
        lump_check(rec, "legs", "legs")


def test_lump_cli_writes_verdict_and_figure(tmp_path, capsys):
    from armaxmodal.cli import main
    from armaxmodal.io.write import write_recording_csv

    _, rec = _feet_ride(True)
    data = write_recording_csv(rec, tmp_path / "ride.csv")
    assert (
        main(
            [
                "lump",
                str(data),
                "legs",
                "feet",
                "--json",
                str(tmp_path / "l.json"),
                "--plot",
                str(tmp_path / "l.png"),
                "--quiet",
            ]
        )
        == 0
    )
    assert "moves apart" in capsys.readouterr().out
    import json

    report = json.loads((tmp_path / "l.json").read_text())
    assert report["verdict"] == "separate" and (tmp_path / "l.png").stat().st_size > 10_000
    assert am.read_recording(data).n_samples == rec.n_samples  # input untouched and readable
