"""Modes out as UFF 55 with the FRFs as UFF 58, and back (``stabilise --uff``, ``invert x.uff``)."""

import json

import numpy as np
import pytest
import pyuff

import armaxmodal as am
from armaxmodal.cli.main import main
from armaxmodal.exceptions import DataError
from armaxmodal.io.uff_modes import read_modes_uff, write_modes_uff
from armaxmodal.modal import normalised_shape


def test_the_modes_of_a_structure_round_trip(tmp_path):
    exact = am.supine_human().modes()
    sensors = ["head", "chest", "pelvis", "legs"]
    f = np.linspace(1.0, 20.0, 39)
    h = np.exp(1j * f)  # any complex FRF
    path = write_modes_uff(tmp_path / "m.uff", exact.freq_hz, exact.damping, exact.modal_constants, sensors,
                           [("measured H1", 2, f, h)])  # fmt: skip
    back = read_modes_uff(path)
    assert back["outputs"] == sensors and len(back["modes"]) == 4
    for m, mode in enumerate(back["modes"]):  # UFF writes 6 significant digits
        assert mode["freq_hz"] == pytest.approx(exact.freq_hz[m], rel=1e-5)
        assert mode["damping"] == pytest.approx(exact.damping[m], rel=1e-4)
        shape = np.array([mode["shape"][s]["mag"] * np.exp(1j * np.radians(mode["shape"][s]["phase_deg"]))
                          for s in sensors])  # fmt: skip
        np.testing.assert_allclose(shape, normalised_shape(exact.modal_constants[:, m]), atol=1e-5)
    (frf,) = [s for s in pyuff.UFF(str(path)).read_sets() if s["type"] == 58]  # read by pyuff as any tool would
    assert frf["func_type"] == 4 and frf["rsp_node"] == 3 and frf["id1"].startswith("measured H1: pelvis / base")
    np.testing.assert_allclose(frf["x"], f)
    np.testing.assert_allclose(frf["data"], h, rtol=1e-5)


def test_many_long_sensor_names_span_the_id_lines_and_bad_ones_are_refused(tmp_path):
    names = [f"accelerometer_{k:02d}_vertical" for k in range(7)]  # two to a line: four lines
    shapes = np.ones((7, 1), complex)
    back = read_modes_uff(write_modes_uff(tmp_path / "a.uff", [5.0], [0.1], shapes, names))
    assert back["outputs"] == names
    with pytest.raises(DataError, match="';' and '='"):
        write_modes_uff(tmp_path / "b.uff", [5.0], [0.1], np.ones((1, 1)), ["head;chest"])
    with pytest.raises(DataError, match="do not fit"):
        write_modes_uff(tmp_path / "c.uff", [5.0], [0.1], np.ones((40, 1)), [f"sensor_{k:03d}" for k in range(40)])
    assert not (tmp_path / "b.uff").exists() and not (tmp_path / "c.uff").exists()


def test_a_uff_without_modes_is_refused(tmp_path, fixtures_dir):
    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    path = am.write_recording_uff(rec, tmp_path / "ride.uff")  # type 58 time histories only
    with pytest.raises(DataError, match="no type-55"):
        read_modes_uff(path)


def test_stabilise_uff_then_invert_reads_it(fixtures_dir, tmp_path, capsys):
    data, uff, js = str(fixtures_dir / "supine_random.csv"), tmp_path / "m.uff", tmp_path / "m.json"
    assert main(["--quiet", "stabilise", data, "--orders", "2:20", "--uff", str(uff), "--json", str(js)]) == 0
    record, back = json.loads(js.read_text()), read_modes_uff(uff)
    assert back["outputs"] == record["outputs"]
    np.testing.assert_allclose([m["freq_hz"] for m in back["modes"]], [m["freq_hz"] for m in record["modes"]],
                               rtol=1e-5)  # fmt: skip
    frfs = [s for s in pyuff.UFF(str(uff)).read_sets() if s["type"] == 58]
    assert len(frfs) == 2 * len(record["outputs"])  # measured and modal model per sensor
    out = tmp_path / "phys.json"
    assert main(["--quiet", "invert", str(uff), "--total-mass", "77.57", "--json", str(out)]) == 0
    assert json.loads(out.read_text())["names"] == record["outputs"]
    capsys.readouterr()
    assert main(["--quiet", "invert", str(tmp_path / "none.uff")]) == 2
    assert "no such file" in capsys.readouterr().err
