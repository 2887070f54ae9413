"""The notes on the terminal: one line per code within 100 characters, labelled by how the code
moves the verdict, the whole block on one screen; every full text under --verbose."""

import numpy as np

import armaxmodal as am
from armaxmodal.cli.common import print_notes
from armaxmodal.cli.main import main
from armaxmodal.quality_warnings import CODES, PROBLEM_CODES, UNCERTAIN_CODES, severity


def _one_of_each() -> list:
    """A note of every code (two of the first), each with a long text."""
    notes = [am.QualityWarning(c.code, ("head",), f"{c.code}: " + "a long measured sentence " * 12) for c in CODES]
    return [notes[0], *notes]


def test_one_line_per_code_on_one_screen_what_moves_the_verdict_first(capsys):
    print_notes(_one_of_each())
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) <= 25 and all(len(line) <= 100 for line in lines), max(map(len, lines))
    n_warnings = sum(severity(c.code) == "warning" for c in CODES) + (severity(CODES[0].code) == "warning")
    assert lines[0].startswith(f"notes: {len(PROBLEM_CODES)} problems, {n_warnings} warnings, ")
    assert lines[-1] == f"  ... {len(CODES) - 23} more codes (--verbose)"
    shown = [line.split()[1] for line in lines[1:-1]]
    labels = [line.split()[0] for line in lines[1:-1]]
    assert labels == [severity(code) for code in shown]
    assert labels == sorted(labels, key=["problem", "warning", "info"].index)  # problems, then warnings
    n_problems, n_uncertain = len(PROBLEM_CODES), len(UNCERTAIN_CODES)
    assert set(shown[n_problems : n_problems + n_uncertain]) == set(UNCERTAIN_CODES)  # then what makes it uncertain
    assert f"{CODES[0].code} (2, head): " in lines[1 + shown.index(CODES[0].code)]
    assert "a long measured sentence" not in "\n".join(lines)  # the full texts are not on the screen


def test_verbose_shows_every_full_text(capsys):
    notes = _one_of_each()
    print_notes(notes, verbose=True)
    err = capsys.readouterr().err
    assert err.count("      - ") == len(notes) and "more codes" not in err
    assert all(f"  {severity(c.code):<8}{c.code} (" in err for c in CODES)
    assert all(len(line) <= 100 for line in err.splitlines() if line.startswith("      "))


def test_a_code_line_names_its_notes_frequencies(capsys):
    def note(code, *freqs):
        return am.QualityWarning(code, (), "text", None, freqs)

    print_notes([note("count_undecided", 28.4838), note("count_undecided", 4.4, 28.4838), note("mode_count"),
                 *(note("unexplained_peak", f) for f in (3.0, 5.5, 7.25, 9.0, 11.75))])  # fmt: skip
    lines = capsys.readouterr().err.splitlines()
    assert lines[1].startswith("  warning count_undecided (2, at 4.4, 28.48 Hz): ")  # each once, in order
    assert lines[2].startswith("  warning unexplained_peak (5, at 5 frequencies 3-11.75 Hz): ")  # more: the range
    assert lines[3].startswith("  info    mode_count (1): ")
    print_notes([note("unexplained_peak", f) for f in (3.0, 5.5, 7.25, 9.0)])  # four: each named
    assert capsys.readouterr().err.splitlines()[1].startswith("  warning unexplained_peak (4, at 3, 5.5, 7.25, 9 Hz): ")
    print_notes([note("mode_count", 0.0041667, 15.7291), note("mode_count", 0.0041667)])  # a drift's pole: not "0"
    assert capsys.readouterr().err.splitlines()[1].startswith("  info    mode_count (2, at 0.00417, 15.73 Hz): ")
    assert note("mode_count", 4.4, np.nan).to_dict()["freq_hz"] == [4.4]  # strict JSON: no NaN


def test_severity_follows_the_verdict():
    assert [severity(c) for c in ("modes_do_not_explain_frf", "count_undecided", "clipping", "resampled")] == [
        "problem", "warning", "warning", "info"]  # fmt: skip
    assert all(severity(c.code) == "warning" for c in CODES if c.uncertain)


def test_stabilise_prints_the_verdict_then_the_notes(fixtures_dir, tmp_path, capsys):
    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    drift = np.linspace(0.0, 2.0, rec.n_samples)[:, None]  # a drifting pelvis: uncertain
    drifted = am.Recording(rec.fs, rec.base, rec.response + drift * (np.arange(4) == 2), rec.sensors)
    path = am.write_recording_csv(drifted, tmp_path / "drift.csv")
    assert main(["stabilise", str(path), "--orders", "2:16"]) == 0
    out, err = capsys.readouterr()
    lines = out.strip().splitlines()  # the read, the modes, the check, the verdict: one screen, with the notes
    assert any(line.startswith("quality: UNCERTAIN") for line in lines[-2:]) and "drift" in out
    err = err[err.index("notes: "):]  # after the progress bars
    assert "\n  warning drift (1, pelvis): Rerun with `--detrend linear`" in err
    shown = lines + err.strip().splitlines()
    assert len(shown) <= 25 and max(map(len, shown)) <= 100, shown
    assert main(["--quiet", "--verbose", "stabilise", str(path), "--orders", "2:16"]) == 0
    assert "      - " in capsys.readouterr().err


#: every code's one severity, as the docs' codes page and the command line label it: a change here
#: is a change of what a user is told to act on, made on purpose
SEVERITIES = {
    "problem": ["no_modes", "modes_do_not_explain_frf"],
    "warning": ["duplicate_channel", "inverted_sensor", "sensor_delay", "narrowband_input", "clipping",
                "dropped_packet", "offset_step", "drift", "model_error_dominates", "nk_at_search_edge",
                "unexplained_peak", "damping_unresolved", "incoherent_output", "unit_mismatch",
                "periodic_disturbance", "stuck_samples", "oversampled", "held_samples", "refit_failed",
                "count_undecided", "modes_not_separated", "pick_not_supported", "mode_beyond_band"],
    "info": ["gap_filled", "empty_columns_dropped", "time_rounded", "offset_removed", "trend_removed", "resampled",
             "split_merged", "mode_not_needed", "orders_capped", "check_not_run", "mode_count", "estimators_disagree"],
}  # fmt: skip


def test_each_code_has_its_one_severity():
    pinned = {code: level for level, codes in SEVERITIES.items() for code in codes}
    assert {c.code: severity(c.code) for c in CODES} == pinned
