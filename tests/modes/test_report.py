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
    for heading in ("The record", "Warnings", "Stabilisation diagram", "Modes (4)", "modal-model check", "Settings"):
        assert heading in html
    assert 'class="verdict good"' in html and "quality: good" in html
    # the modes table holds the JSON's numbers
    record = __import__("json").loads((tmp_path / "m.json").read_text())
    for mode in record["modes"]:
        assert f"{mode['freq_hz']:.5g}" in html
    dom, console_errors = open_in_headless_chromium(page, tmp_path / "profile")
    assert 'data-figures="2/2"' in dom and not console_errors


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
