import json

import numpy as np

import armaxmodal as am
from armaxmodal.cli import main


def test_info(fixtures_dir, capsys):
    assert main(["info", str(fixtures_dir / "supine_random.csv")]) == 0
    out = capsys.readouterr().out
    assert "7200 samples at 60 Hz" in out and "legs" in out


def test_modes_json(tmp_path, capsys):
    out = tmp_path / "modes.json"
    assert main(["--quiet", "modes", "--system", "supine", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    np.testing.assert_allclose([m["freq_hz"] for m in data["modes"]], am.supine_human().modes().freq_hz)


def test_simulate_writes_a_readable_recording(tmp_path):
    out = tmp_path / "sim.csv"
    assert (
        main(
            [
                "--quiet",
                "simulate",
                "--system",
                "chapter2",
                "--fs",
                "100",
                "--duration",
                "5",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    rec = am.read_recording(out)
    assert rec.n_samples == 500 and rec.sensors == ("m1", "m2", "m3", "m4")


def test_errors_exit_2_with_a_message(tmp_path, capsys):
    p = tmp_path / "r.csv"
    p.write_text("time,plat,a\n0,1,2\n1,2,3\n2,0,1\n")
    assert main(["info", str(p)]) == 2
    err = capsys.readouterr().err
    assert "input channel 'base' not found" in err and "--input" in err
    assert main(["info", str(p), "--input", "plat"]) == 0
