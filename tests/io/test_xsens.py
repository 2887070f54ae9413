"""Xsens DOT exports: synthetic files with planted defects, and the real shake-table runs."""

import gzip
import json

import numpy as np
import pytest

from armaxmodal.cli import main
from armaxmodal.exceptions import DataError
from armaxmodal.io.xsens import read_xsens

STEP_US = 8333
META = "sep=,\nDeviceTag:,Xsens DOT\nFirmwareVersion:,3.0.0\nAppVersion:,2023.6.0\nStartTime: ,x\n© Movella\n\n"
HEADER = "PacketCounter,SampleTimeFine,Euler_X,Euler_Y,Euler_Z,Acc_X,Acc_Y,Acc_Z,Gyr_X,Gyr_Y,Gyr_Z\n"
# Reference fundamental periods of the 3-storey models (mdof solution notebook): within 3 %
REAL_PERIOD_RTOL = 0.03


def _export(path, t0_us, acc_x, drop=(), step_us=STEP_US):
    """An export whose first packet is all zeros, then ``acc_x`` sample by sample; packets
    whose index is in ``drop`` are missing."""
    lines = [META, HEADER, f"0,{t0_us - step_us},0,0,0,0,0,0,0,0,0\n"]
    for i, a in enumerate(acc_x):
        if i not in drop:
            lines.append(f"{i + 1},{round(t0_us + i * step_us)},0,0,0,{float(a)!r},0.1,9.8,0,0,0\n")
    with gzip.open(path, "wt", encoding="utf-8") as fh:
        fh.write("".join(lines))
    return path


@pytest.fixture
def signals():
    rng = np.random.default_rng(1)
    return rng.standard_normal(400), rng.standard_normal(400)


def test_sensors_are_put_on_the_inputs_stamps(tmp_path, signals):
    u, y = signals
    g = _export(tmp_path / "run__g.csv.gz", 10_000_000, u)
    # the floor sensor started one packet later: its first value belongs to the input's second stamp
    f1 = _export(tmp_path / "run__f1.csv.gz", 10_000_000 + STEP_US, y[1:])
    rec = read_xsens([g, f1], input="g")
    assert rec.input_name == "g" and rec.sensors == ("f1",)
    assert rec.fs == pytest.approx(1e6 / STEP_US)
    np.testing.assert_allclose(rec.base, u[1:])
    np.testing.assert_allclose(rec.response[:, 0], y[1:])
    assert rec.meta["read_warnings"] == []


def test_a_short_gap_is_bridged_and_flagged_a_long_one_refused(tmp_path, signals):
    u, y = signals
    g = _export(tmp_path / "g.csv.gz", 0, u)
    f1 = _export(tmp_path / "f1.csv.gz", 0, y, drop={100, 101})
    rec = read_xsens({"g": g, "f1": f1}, input="g")
    (note,) = rec.meta["read_warnings"]
    assert note.code == "dropped_packet" and note.channels == ("f1",) and note.value == 2
    np.testing.assert_allclose(rec.response[100:102, 0], y[99] + (y[102] - y[99]) * np.array([1, 2]) / 3)
    np.testing.assert_allclose(rec.response[:100, 0], y[:100])
    long_gap = _export(tmp_path / "f2.csv.gz", 0, y, drop=set(range(100, 110)))
    with pytest.raises(DataError, match="10 packets missing"):
        read_xsens({"g": g, "f2": long_gap}, input="g")


def test_a_sensor_at_another_rate_is_refused_a_drifting_clock_is_not(tmp_path, signals):
    """A sensor exported at 60 Hz beside 120 Hz ones was linearly interpolated onto the
    input's stamps without a word; a clock 100 ppm fast is what stamps are aligned for."""
    u, y = signals
    g = _export(tmp_path / "g.csv.gz", 0, u)
    half = _export(tmp_path / "f1.csv.gz", 0, y[:200], step_us=2 * STEP_US)
    with pytest.raises(DataError, match="different rates: 'f1' 60 Hz, the input 'g' 120 Hz"):
        read_xsens({"g": g, "f1": half}, input="g")
    fast = _export(tmp_path / "f2.csv.gz", 0, y, step_us=STEP_US * (1 + 1e-4))
    rec = read_xsens({"g": g, "f2": fast}, input="g")
    assert rec.fs == pytest.approx(1e6 / STEP_US) and rec.n_samples == u.size  # every input stamp


def test_bad_exports_are_typed_errors(tmp_path, signals):
    u, _ = signals
    g = _export(tmp_path / "g.csv.gz", 0, u)
    plain = tmp_path / "plain.csv"
    plain.write_text("time,base,a\n0,1,2\n")
    with pytest.raises(DataError, match="PacketCounter"):
        read_xsens({"g": g, "p": plain}, input="g")
    with pytest.raises(DataError, match="not among"):
        read_xsens({"g": g, "h": g}, input="base")
    with pytest.raises(DataError, match="Acc_Q"):
        read_xsens({"g": g, "h": g}, input="g", axis="Acc_Q")


@pytest.mark.parametrize("model, period_s", [("flex3", 0.274), ("stiff3", 0.127)])
def test_real_runs_through_the_cli(realdata_dir, tmp_path, model, period_s):
    folder = realdata_dir / "mini_shake_table_imu" / model
    files = [str(folder / f"northridge__{s}.csv.gz") for s in ("g", "f1", "f2", "f3")]
    out = tmp_path / "m.json"
    assert main(["--quiet", "stabilise", *files, "--input", "g", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["input"] == "g" and data["outputs"] == ["f1", "f2", "f3"]
    assert len(data["modes"]) == 3
    assert abs(data["modes"][0]["freq_hz"] * period_s - 1) < REAL_PERIOD_RTOL
