"""The mode-shape figure (``stabilise --shapes-plot``): it draws the shapes the JSON reports."""

import json

import numpy as np
import pytest

import armaxmodal as am
from armaxmodal.cli.main import main
from armaxmodal.io.report.shape_plot import plot_shapes
from armaxmodal.modal import normalised_shape


def test_normalised_shape_puts_the_largest_component_at_one():
    phi = normalised_shape(np.array([0.5j, -2.0 + 0j, 1.0 + 1.0j]))
    assert phi[1] == 1.0 and np.allclose(phi, [-0.25j, 1.0, -0.5 - 0.5j])
    assert np.all(normalised_shape(np.zeros(3)) == 0)


@pytest.fixture(scope="module")
def selection(fixtures_dir):
    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    return am.select_modes(am.stabilisation_diagram(rec, range(2, 21, 2), per_sensor=False), segments=0)


def test_each_column_draws_its_modes_normalised_shape(selection):
    fig = plot_shapes(selection)
    top = fig.axes[: len(selection.modes)]  # the first row: real part, then magnitude
    for k, ax in enumerate(top):
        phi = normalised_shape(selection.shapes[:, k])
        real, magnitude = (line.get_ydata() for line in ax.lines[1:3])
        np.testing.assert_allclose(real, phi.real)
        np.testing.assert_allclose(magnitude, np.abs(phi))
        assert f"{selection.modes.freq_hz[k]:.2f} Hz" in ax.get_title()
    phases = fig.axes[len(selection.modes)].lines[1].get_ydata()
    np.testing.assert_allclose(phases, np.degrees(np.angle(normalised_shape(selection.shapes[:, 0]))))
    assert [t.get_text() for t in fig.axes[-1].get_xticklabels()] == list(selection.diagram.recording.sensors)


def test_stabilise_writes_the_shapes_figure(fixtures_dir, tmp_path, capsys):
    data, png, out = str(fixtures_dir / "supine_random.csv"), tmp_path / "shapes.png", tmp_path / "m.json"
    assert main(["--quiet", "stabilise", data, "--orders", "2:20", "--shapes-plot", str(png), "--json", str(out)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and len(json.loads(out.read_text())["modes"]) == 4
    capsys.readouterr()
    assert main(["--quiet", "stabilise", data, "--shapes-plot", str(tmp_path / "s.jpg")]) == 2
    assert "--shapes-plot: expected a .png, .svg or .pdf" in capsys.readouterr().err


def test_with_positions_the_top_row_draws_the_deflected_chain(selection):
    positions = {"head": 1.7, "chest": 1.3, "pelvis": 0.9, "legs": 0.4}
    fig = plot_shapes(selection, positions=positions)
    for k, ax in enumerate(fig.axes[: len(selection.modes)]):
        rest, deflected = ax.lines[:2]
        phi = normalised_shape(selection.shapes[:, k])
        order = np.argsort([positions[s] for s in selection.diagram.recording.sensors])
        np.testing.assert_allclose(deflected.get_ydata(), [0.4, 0.9, 1.3, 1.7])
        np.testing.assert_allclose(deflected.get_xdata(), phi.real[order])
        assert np.all(rest.get_xdata() == 0)


@pytest.mark.parametrize("argv, message", [
    (["--positions", "head=1"], "give --shapes-plot FILE as well"),
    (["--shapes-plot", "s.png", "--positions", "head=1,chest=2,pelvis=3"], "missing ['legs']"),
    (["--shapes-plot", "s.png", "--positions", "head=1,chest=2,pelvis=3,legs=4,feet=5"], "not a sensor ['feet']"),
    (["--shapes-plot", "s.png", "--positions", "head:1"], "expected NAME=VALUE pairs"),
])  # fmt: skip
def test_bad_positions_are_refused_before_the_sweep(fixtures_dir, tmp_path, capsys, argv, message):
    assert main(["--quiet", "stabilise", str(fixtures_dir / "supine_random.csv"), *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
