import json
import os
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

import armaxmodal as am

NAMES = ["supine_random", "supine_sweep", "supine_random_zoh", "chapter2_random_zoh"]
# The CSVs are printed with 8 significant digits; a LAPACK build may differ in the last
# digit of an eigenvector phase, so regenerated files are compared as numbers, not bytes.
CSV_RTOL = 1e-6
JSON_RTOL = 1e-9


def _assert_json_close(got, want, where=""):
    if isinstance(want, dict):
        assert isinstance(got, dict) and got.keys() == want.keys(), where
        for key in want:
            _assert_json_close(got[key], want[key], f"{where}.{key}")
    elif isinstance(want, list):
        assert isinstance(got, list) and len(got) == len(want), where
        for i, (g, w) in enumerate(zip(got, want, strict=True)):
            _assert_json_close(g, w, f"{where}[{i}]")
    elif isinstance(want, float | int) and not isinstance(want, bool):
        np.testing.assert_allclose(got, want, rtol=JSON_RTOL, atol=1e-12, err_msg=where)
    else:
        assert got == want, where


def test_fixtures_regenerate(tmp_path, fixtures_dir):
    script = fixtures_dir.parent / "tools" / "make_fixtures.py"
    # run from anywhere, against this checkout's package (not whatever an earlier install left)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(fixtures_dir.parent), os.environ.get("PYTHONPATH", "")]))
    subprocess.run(
        [sys.executable, str(script), "--out", str(tmp_path)], check=True, capture_output=True, env=env, cwd=tmp_path
    )
    for name in NAMES:
        got = pd.read_csv(tmp_path / f"{name}.csv", comment="#")
        want = pd.read_csv(fixtures_dir / f"{name}.csv", comment="#")
        assert list(got.columns) == list(want.columns), name
        np.testing.assert_allclose(got.to_numpy(), want.to_numpy(), rtol=CSV_RTOL, atol=1e-9, err_msg=name)
        _assert_json_close(
            json.loads((tmp_path / f"{name}.truth.json").read_text()),
            json.loads((fixtures_dir / f"{name}.truth.json").read_text()),
            name,
        )


def test_regeneration_check_catches_a_changed_number(fixtures_dir):
    want = json.loads((fixtures_dir / "supine_random.truth.json").read_text())
    got = json.loads(json.dumps(want))
    got["modes"][0]["freq_hz"] *= 1 + 1e-6
    with pytest.raises(AssertionError):
        _assert_json_close(got, want)


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
