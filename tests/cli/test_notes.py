"""The notes on the terminal: one line per code, what was found within 100 characters, labelled by
how the code moves the verdict, the whole block on one screen; what to do and every full text
under --verbose. ``stabilise`` on the bundled ride and on two measured records fits one screen."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import armaxmodal as am
from armaxmodal.cli.common import NOTE_LINES, headline, print_notes
from armaxmodal.cli.main import main
from armaxmodal.quality_warnings import CODES, PROBLEM_CODES, UNCERTAIN_CODES, severity


def _one_of_each() -> list:
    """A note of every code (two of the first), each with a long text."""
    notes = [am.QualityWarning(c.code, ("head",), f"{c.code}: " + "a long measured sentence " * 12) for c in CODES]
    return [notes[0], *notes]


def test_each_code_says_what_was_found_on_one_screen_what_moves_the_verdict_first(capsys):
    print_notes(_one_of_each())
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) <= 25 and all(len(line) <= 100 for line in lines), max(map(len, lines))
    n_warnings = sum(severity(c.code) == "warning" for c in CODES) + (severity(CODES[0].code) == "warning")
    assert lines[0].startswith(f"notes: {len(PROBLEM_CODES)} problems, {n_warnings} warnings, ")
    heads = lines[1:-1]
    shown = [line.split()[1] for line in heads]
    assert lines[-1] == f"  ... {len(CODES) - len(shown)} more codes (--verbose)"
    labels = [line.split()[0] for line in heads]
    assert labels == [severity(code) for code in shown]
    assert labels == sorted(labels, key=["problem", "warning", "info"].index)  # problems, then warnings
    n_problems, n_uncertain = len(PROBLEM_CODES), len(UNCERTAIN_CODES)
    assert set(shown[n_problems : n_problems + n_uncertain]) == set(UNCERTAIN_CODES)  # then what makes it uncertain
    first = CODES[0].code
    assert f"{first} (2, head): {first}: a long measured sentence" in heads[shown.index(first)]  # the finding
    assert heads[shown.index(first)].endswith(" ... (+1 more)")  # cut to leave room for the others' count
    assert len(heads) == NOTE_LINES  # as many codes as fit the screen, a line each


def test_a_few_codes_say_what_was_found_a_line_each(capsys):
    notes = [am.QualityWarning("sensor_delay", ("head",), "'head' lags input 'base' by 32.9 ms (95 % interval 32.2 "
                               "to 33.5 ms). Aligned by 2 samples."),
             am.QualityWarning("offset_removed", ("head",), "removed each channel's mean; large offsets: head +9.81"),
             am.QualityWarning("dropped_packet", (), "2 sample(s) missing at 49.983 s; bridged by linear "
                               "interpolation. " + "The bridged samples enter the fit as data. " * 5)]  # fmt: skip
    print_notes(notes)
    lines = capsys.readouterr().err.splitlines()
    assert lines[0] == "notes: 2 warnings, 1 info (what to do, full texts: --verbose, --json, --report)"
    assert lines[1] == "  warning dropped_packet (1): 2 sample(s) missing at 49.983 s; bridged by linear interpolation."
    assert lines[2] == "  warning sensor_delay (1, head): 'head' lags input 'base' by 32.9 ms. Aligned by 2 samples."
    assert lines[3:] == ["  info    offset_removed (1, head): removed each channel's mean; large offsets: head +9.81"]


def test_a_headline_keeps_the_finding_drops_the_asides_and_says_where_it_was_cut():
    text = ("'head' lags input 'base' by 32.9 ms (95 % interval 32.2 to 33.5 ms, 1.97 samples; phase slope "
            "(Hann lines) up to 4.47 Hz). Aligned by 2 samples.")  # fmt: skip
    assert headline(text, 100) == "'head' lags input 'base' by 32.9 ms. Aligned by 2 samples."  # nested asides too
    assert headline(text, 40) == "'head' lags input 'base' by 32.9 ms."  # a whole sentence: no mark
    assert headline("2 sample(s) missing at 49.98 s; bridged by interpolation", 100) == (
        "2 sample(s) missing at 49.98 s; bridged by interpolation")  # "(s)" is no aside
    cut = headline("2 sample(s) missing at 49.98 s; bridged by interpolation", 40)
    assert cut == "2 sample(s) missing at 49.98 s ..."
    assert headline("offsets: head +9.81, chest +9.81, pelvis +9.81, legs +9.81", 40) == (
        "offsets: head +9.81, chest +9.81 ...")  # a list cut between its items
    assert headline("one long clause without any stop in it at all", 20) == "one long clause ..."
    assert headline("abcdefgh, ijkl mnop qrst", 10) == "abcdef ..."  # the mark fits the width too
    with pytest.raises(ValueError, match="at least 10"):
        headline("text", 9)


def test_a_finding_of_long_words_keeps_to_its_line(capsys):
    print_notes([am.QualityWarning("drift", ("pelvis",), " ".join(["a-measured-quantity-named"] * 40))])
    lines = capsys.readouterr().err.splitlines()[1:]
    assert len(lines) == 1 and lines[0].startswith("  warning drift (1, pelvis): a-measured")
    assert lines[0].endswith(" ...") and len(lines[0]) <= 100


@given(st.text(alphabet=st.sampled_from(list("ab .,:;()")), max_size=300), st.integers(10, 120))
def test_a_headline_never_exceeds_its_width(text, width):
    assert len(headline(text, width)) <= width


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
    assert lines[1] == "  warning count_undecided (2, at 4.4, 28.48 Hz): text (+1 more)"  # each once, in order
    assert lines[2] == "  warning unexplained_peak (5, at 5 frequencies 3-11.75 Hz): text (+4 more)"  # more: the range
    assert lines[3] == "  info    mode_count (1): text"
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
    assert "\n  warning drift (1, pelvis): a linear drift remains after the mean was removed ...\n" in err
    shown = lines + err.strip().splitlines()
    assert len(shown) <= 25 and max(map(len, shown)) <= 100, shown
    assert main(["--quiet", "--verbose", "stabilise", str(path), "--orders", "2:16"]) == 0
    err = capsys.readouterr().err
    assert "      - " in err and "Rerun with `--detrend linear`" in err  # what to do, under --verbose


@pytest.mark.parametrize(
    "record",
    ["bridge_capistrano/capistrano_inglewood.csv", "bridge_painter/painter_nc73666231.csv.gz"],
)
def test_stabilise_on_a_measured_record_fits_one_screen(realdata_dir, record, capsys):
    """The two measured records whose notes ran longest (28 and 30 lines before a line a code)."""
    assert main(["--quiet", "stabilise", str(realdata_dir / record)]) == 0
    out, err = capsys.readouterr()
    shown = out.strip().splitlines() + err.strip().splitlines()
    assert len(shown) <= 25 and max(map(len, shown)) <= 100, shown
    assert any(line.startswith("quality: ") for line in shown) and shown[-1].startswith("  ")


#: every code's one severity, as the docs' codes page and the command line label it: a change here
#: is a change of what a user is told to act on, made on purpose
SEVERITIES = {
    "problem": ["no_modes", "modes_do_not_explain_frf"],
    "warning": ["duplicate_channel", "inverted_sensor", "sensor_delay", "narrowband_input", "clipping",
                "dropped_packet", "offset_step", "drift", "model_error_dominates", "nk_at_search_edge",
                "unexplained_peak", "damping_unresolved", "incoherent_output", "unit_mismatch",
                "periodic_disturbance", "stuck_samples", "oversampled", "held_samples", "refit_failed",
                "count_undecided", "modes_not_separated", "pick_not_supported", "mode_beyond_band",
                "undriven_resonance"],
    "info": ["gap_filled", "empty_columns_dropped", "time_rounded", "offset_removed", "trend_removed", "resampled",
             "split_merged", "mode_not_needed", "orders_capped", "check_not_run", "mode_count", "estimators_disagree",
             "model_inadequate"],
}  # fmt: skip


def test_each_code_has_its_one_severity():
    pinned = {code: level for level, codes in SEVERITIES.items() for code in codes}
    assert {c.code: severity(c.code) for c in CODES} == pinned


def test_quiet_turns_the_progress_off_not_the_result(fixtures_dir, capsys):
    """Under --quiet the mode table, the check and the verdict print; no progress bar does."""
    assert main(["stabilise", str(fixtures_dir / "supine_random.csv"), "--orders", "2:12", "--quiet"]) == 0
    out, err = capsys.readouterr()
    assert "mode    f (Hz)" in out and "modal-model check" in out and "quality: " in out
    assert "fit/s" not in err and "%|" not in err


def test_a_mode_the_count_added_shows_no_orders_and_says_why(capsys):
    """A diagram cluster's mode prints the orders that hold it; a mode the modal model's count added
    (no cluster: ``count`` 0) prints "-" and one line under the table, never a 0 that reads as a
    mode no order supports."""
    import pandas as pd

    from armaxmodal.cli.stabilise import print_modes

    modes = pd.DataFrame({"freq_hz": [5.83, 6.41], "freq_ci95_lo": [5.82, 6.30], "freq_ci95_hi": [5.84, 6.52],
                          "damping": [0.26, 0.02], "damping_ci95_lo": [0.25, 0.01], "damping_ci95_hi": [0.27, 0.03],
                          "count": [14, 0]})  # fmt: skip
    print_modes(modes)
    first, second, note = capsys.readouterr().out.splitlines()[1:]
    assert first.split()[-1] == "14" and second.split()[-1] == "-"
    assert note == "  orders -: added by the modal model's count; no column of the diagram holds it"
    print_modes(modes.iloc[:1])
    assert len(capsys.readouterr().out.splitlines()) == 2  # no such mode: no line
