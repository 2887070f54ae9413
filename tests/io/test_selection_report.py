"""The one-record report (``stabilise --report``) and the notebook view of a selection."""

import re

import pytest

import armaxmodal as am
from armaxmodal.cli.main import main
from tests.conftest import open_in_headless_chromium


def test_stabilise_writes_a_self_contained_report_a_browser_shows(fixtures_dir, tmp_path):
    data, page = str(fixtures_dir / "supine_random.csv"), tmp_path / "run.html"
    assert main(["--quiet", "stabilise", data, "--orders", "2:20", "--report", str(page), "--json",
                 str(tmp_path / "m.json")]) == 0  # fmt: skip
    html = page.read_text()
    assert "http://" not in html and "https://" not in html  # nothing fetched
    assert html.count("src='data:image/png;base64,") == 2  # the diagram and the shapes
    for key, heading in (("record", "The record"), ("notes", "Notes"), ("diagram", "Stabilisation diagram"),
                         ("modes", "Modes (4)"), ("check", "The modal-model check"), ("settings", "Settings")):
        assert f"<h2 id={key}>{heading}" in html and f"<a href='#{key}'>{heading}" in html  # navigated to
    assert 'class="verdict good"' in html and "quality: good" in html
    # what made it: the version, the command as run, the input's checksum
    from armaxmodal.study.manifest import content_hash

    assert f"<td>{am.__version__}</td>" in html and f"{content_hash(fixtures_dir / 'supine_random.csv')}" in html
    assert f"armaxmodal --quiet stabilise {data} --orders 2:20 --report {page}" in html
    # a setting the run did not use is left out, not shown empty; no picks, no picks column
    assert "band (Hz)" not in html and "picked at" not in html and "picks (Hz)" not in html
    assert "<td>detrend</td>" in html
    # the modes table holds the JSON's numbers, each quantity at one precision (its interval too)
    record = __import__("json").loads((tmp_path / "m.json").read_text())
    for mode in record["modes"]:
        lo, hi = mode["freq_ci95"]
        assert f"<td>{mode['freq_hz']:.3f}</td>" in html and f"<td>[{lo:.3f}, {hi:.3f}]</td>" in html
        assert f"<td>{mode['damping']:.4f}</td>" in html
    # a glossary of its terms, the one the docs print
    from armaxmodal.io.report.glossary import TERMS

    assert "<h2 id=glossary>Glossary" in html and all(f"<dt>{term}</dt>" in html for term in ("H1", "LSFD", "nk"))
    assert len(TERMS) >= 15
    for width in (390, 1400):  # a phone and a desktop: nothing runs off the screen, the figures load
        dom, console_errors = open_in_headless_chromium(page, tmp_path / f"profile{width}", width)
        assert 'data-figures="2/2"' in dom and 'data-overflow="no"' in dom and not console_errors


@pytest.mark.parametrize("report, message", [("run.txt", "expected an .html file name"),
                                             ("missing/run.html", "does not exist; create it first")])
def test_a_bad_report_path_is_refused_before_the_sweep(fixtures_dir, tmp_path, capsys, report, message):
    assert main(["--quiet", "stabilise", str(fixtures_dir / "supine_random.csv"), "--report",
                 str(tmp_path / report)]) == 2  # fmt: skip
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not list(tmp_path.iterdir())  # nothing written


def test_a_notebook_shows_the_verdict_and_the_modes(fixtures_dir):
    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    sel = am.select_modes(am.stabilisation_diagram(rec, range(2, 21, 2), per_sensor=False), segments=0)
    shown = sel._repr_html_()
    assert sel.verdict.startswith("quality: good") and sel.verdict in shown
    assert len(re.findall(r"<tr[ >]", shown)) == 1 + len(sel.modes)  # header and one row per mode


def test_the_report_groups_the_notes_by_code_what_moves_the_verdict_first(tmp_path):
    """Three notes of two codes: one group per code with its count, the code that makes the verdict
    uncertain first and open, its advice, and every full text."""
    from armaxmodal.io.report.selection_report import _notes

    notes = [am.QualityWarning("resampled", (), "resampled by 1/9"),
             am.QualityWarning("count_undecided", (), "first text"), am.QualityWarning("count_undecided", (), "second")]
    html = _notes(notes)
    assert html.index("count_undecided") < html.index("resampled")
    assert "<details open><summary><b>count_undecided</b> (2): makes the verdict uncertain" in html
    assert "<details><summary><b>resampled</b> (1): informative" in html
    assert "<li>first text</li><li>second</li>" in html and "<li>resampled by 1/9</li>" in html
    from armaxmodal.io.report.html_page import marked_up
    from armaxmodal.quality_warnings import CODES

    advice = next(c.advice for c in CODES if c.code == "count_undecided")
    assert f"<p>{marked_up(advice)}</p>" in html
    notes = [am.QualityWarning("drift", ("pelvis",), "rerun with `--detrend linear` & look")]
    assert "<li>rerun with <code>--detrend linear</code> &amp; look</li>" in _notes(notes)  # no raw backticks


def test_the_report_of_an_uncertain_run_shows_its_notes_in_a_browser(fixtures_dir, tmp_path):
    """A drifting pelvis makes the run uncertain: the page, as headless Chromium renders it, holds
    the verdict, the notes that make it so with their full texts, and what made it (version, date,
    command)."""
    import numpy as np

    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    drift = np.linspace(0.0, 2.0, rec.n_samples)[:, None] * (np.arange(4) == 2)
    path = am.write_recording_csv(am.Recording(rec.fs, rec.base, rec.response + drift, rec.sensors),
                                  tmp_path / "drift.csv")  # fmt: skip
    page = tmp_path / "run.html"
    assert main(["--quiet", "stabilise", str(path), "--orders", "2:16", "--report", str(page)]) == 0
    dom, console_errors = open_in_headless_chromium(page, tmp_path / "profile")
    assert not console_errors and 'class="verdict uncertain"' in dom and "quality: UNCERTAIN" in dom
    notes = dom[dom.index("<h2 id=\"notes\">") if "<h2 id=\"notes\">" in dom else dom.index("<h2 id=notes>"):]
    assert "<b>drift</b> (1): makes the verdict uncertain" in notes and "pelvis" in notes
    assert f"<td>{am.__version__}</td>" in dom and "run at (UTC)" in dom
    assert f"armaxmodal --quiet stabilise {path} --orders 2:16 --report {page}" in dom


def test_the_report_leaves_no_figure_open(fixtures_dir):
    """The page embeds its two figures and closes them: a notebook or a gallery calling it keeps no
    stray figure (the gallery showed the report's diagram and shapes as figures of its own)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from armaxmodal.io.report.selection_report import render_selection_report

    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    selection = am.select_modes(am.stabilisation_diagram(rec, range(4, 13, 2), per_sensor=False), segments=0)
    plt.close("all")
    page = render_selection_report(selection, "quality: good", "supine_random.csv")
    assert page.count("data:image/png;base64,") == 2 and plt.get_fignums() == []
