import json
import subprocess
import sys

import numpy as np
import pytest

import armaxmodal as am

NAMES = ["supine_random", "supine_sweep", "supine_random_zoh", "chapter2_random_zoh"]


def test_fixtures_regenerate_byte_for_byte(tmp_path, fixtures_dir):
    script = fixtures_dir.parent / "scripts" / "make_fixtures.py"
    subprocess.run([sys.executable, str(script), "--out", str(tmp_path)], check=True, capture_output=True)
    for name in NAMES:
        for suffix in (".csv", ".truth.json"):
            assert (tmp_path / f"{name}{suffix}").read_bytes() == (fixtures_dir / f"{name}{suffix}").read_bytes(), (
                name + suffix
            )


@pytest.mark.parametrize("name", NAMES)
def test_fixture_truth_matches_its_structure(fixtures_dir, name):
    truth = json.loads((fixtures_dir / f"{name}.truth.json").read_text())
    st = truth["structure"]
    s = am.Structure(st["M"], st["C"], st["K"], truth["outputs"])
    np.testing.assert_allclose([m["freq_hz"] for m in truth["modes"]], s.modes().freq_hz, rtol=1e-12)
    rec = am.read_recording(fixtures_dir / f"{name}.csv")
    assert rec.fs == pytest.approx(truth["fs"], rel=1e-9)
    assert rec.n_samples == int(truth["fs"] * truth["duration_s"])
    assert list(rec.sensors) == truth["outputs"]
