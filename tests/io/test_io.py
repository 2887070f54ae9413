import gzip
import hashlib
import re

import numpy as np
import pandas as pd
import pytest
import scipy.io

import armaxmodal as am
from armaxmodal.exceptions import DataError


@pytest.fixture
def rec():
    s = am.supine_human()
    u = am.random_vibration(60.0, 10.0, seed=1)
    r = am.simulate_recording(s, u, 60.0, noise=0.02, seed=2)
    return am.Recording(r.fs, r.base, r.response, r.sensors, subject="S3", mass_kg=76.96)


def _write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_csv_round_trip_with_subject(tmp_path, rec):
    path = am.write_recording_csv(rec, tmp_path / "r.csv")
    back = am.read_recording(path)
    assert back.fs == pytest.approx(60.0, rel=1e-9)
    assert back.sensors == rec.sensors and back.input_name == "base"
    np.testing.assert_allclose(back.response, rec.response, rtol=1e-8)
    np.testing.assert_allclose(back.base, rec.base, rtol=1e-8)
    assert back.subject == "S3" and back.mass_kg == pytest.approx(76.96)


def test_csv_gz_and_fs_without_time(tmp_path):
    p = tmp_path / "r.csv.gz"
    with gzip.open(p, "wt") as fh:
        fh.write("plat,a,b\n1,2,3\n2,3,4\n0,1,1\n")
    r = am.read_recording(p, input="plat", fs=100.0)
    assert r.fs == 100.0 and r.sensors == ("a", "b")
    np.testing.assert_array_equal(r.base, [1, 2, 0])


@pytest.mark.parametrize(
    ("name", "scale"),
    [("time (s)", 1), ("Time [s]", 1), ("time_ms", 1e3), ("Time (ms)", 1e3), ("t_us", 1e6), ("timestamp [µs]", 1e6)],
)
def test_a_time_column_named_with_its_unit_is_the_time_base(tmp_path, rec, name, scale):
    """Exports name the time column with its unit; one in ms read as a sensor gave a ramp
    'output' (and, without --fs, no sampling rate)."""
    path = am.write_recording_csv(rec, tmp_path / "r.csv")
    frame = pd.read_csv(path, comment="#")
    frame.insert(0, name, frame.pop("time") * scale)
    frame.to_csv(tmp_path / "u.csv", index=False)
    back = am.read_recording(tmp_path / "u.csv")
    assert back.fs == pytest.approx(60.0, rel=1e-9) and back.sensors == rec.sensors
    scipy.io.savemat(tmp_path / "u.mat", {"time_ms": rec.time * 1e3, "base": rec.base, "head": rec.response[:, 0]})
    assert am.read_recording(tmp_path / "u.mat").fs == pytest.approx(60.0, rel=1e-9)


def test_a_row_index_or_unnamed_time_axis_is_not_an_output(tmp_path, rec):
    """pandas writes its index as an unnamed first column by default; read as an output it
    was a ramp that cost the supine ride two of its four modes, and so was a time column
    under a name not known as one ('elapsed_s'). A column increasing in equal steps is left
    out (and listed) unless the user names it; with no time base it is named in the error."""
    path = am.write_recording_csv(rec, tmp_path / "r.csv")
    frame = pd.read_csv(path, comment="#")
    frame.to_csv(tmp_path / "indexed.csv")  # index=True: a first column "", 0..n-1
    frame.insert(1, "sample", np.arange(1, len(frame) + 1))
    frame.to_csv(tmp_path / "counted.csv", index=False)
    for name, axis in (("indexed.csv", "Unnamed: 0"), ("counted.csv", "sample")):
        back = am.read_recording(tmp_path / name)
        assert back.sensors == rec.sensors and back.meta["axis_columns"] == (axis,)
        np.testing.assert_allclose(back.response, rec.response, rtol=1e-8)
    named = am.read_recording(tmp_path / "counted.csv", outputs=["head", "sample"])
    assert named.sensors == ("head", "sample") and named.meta["axis_columns"] == ()
    frame.pop("sample")
    elapsed = frame.rename(columns={"time": "elapsed_s"})
    elapsed.to_csv(tmp_path / "elapsed.csv", index=False)
    back = am.read_recording(tmp_path / "elapsed.csv", fs=60.0)
    assert back.sensors == rec.sensors and back.meta["axis_columns"] == ("elapsed_s",)
    with pytest.raises(DataError, match=r"\['elapsed_s'\] increase in equal steps: if one is the time, name it"):
        am.read_recording(tmp_path / "elapsed.csv")
    # a constant column is a dead sensor (refused by name before a fit), not an axis left out
    frame["sample"] = 1.0
    frame.to_csv(tmp_path / "flat.csv", index=False)
    assert am.read_recording(tmp_path / "flat.csv").sensors == (*rec.sensors, "sample")
    # one step twice as long, or a step back, is data, not an axis
    for column in (np.r_[0, np.arange(2, len(frame) + 1)], np.r_[np.arange(len(frame) - 1), 0]):
        frame["sample"] = column
        frame.to_csv(tmp_path / "near.csv", index=False)
        assert am.read_recording(tmp_path / "near.csv").sensors == (*rec.sensors, "sample")


@pytest.mark.parametrize(("time_unit", "scale"), [("s", 1.0), ("(ms)", 1e3), ("[us]", 1e6)])
def test_a_row_of_units_under_the_header_is_read_as_units(tmp_path, rec, time_unit, scale):
    """Exports often put a row of units under the names ('s, m/s^2'): it was refused as a
    non-numeric cell. Its time unit sets the time base."""
    path = am.write_recording_csv(rec, tmp_path / "r.csv")
    frame = pd.read_csv(path, comment="#")
    frame["time"] *= scale
    units = [time_unit] + ["m/s^2"] * (frame.shape[1] - 1)
    with open(tmp_path / "u.csv", "w") as fh:
        fh.write(",".join(frame.columns) + "\n" + ",".join(units) + "\n")
        frame.to_csv(fh, header=False, index=False)
    back = am.read_recording(tmp_path / "u.csv")
    assert back.fs == pytest.approx(60.0, rel=1e-9) and back.sensors == rec.sensors
    assert back.meta["units"]["head"] == "m/s^2" and back.n_samples == rec.n_samples
    np.testing.assert_allclose(back.response, rec.response, rtol=1e-8)
    # a text cell in the first data row alone is still a bad cell, named
    with open(tmp_path / "bad.csv", "w") as fh:
        fh.write(",".join(frame.columns) + "\n" + ",".join(["0"] + units[1:]) + "\n")
        frame.to_csv(fh, header=False, index=False)
    with pytest.raises(DataError, match="data row 1: 'm/s\\^2' is not a number"):
        am.read_recording(tmp_path / "bad.csv")
    # two text rows: not a row of units over numbers; the first wrong cell is named
    with open(tmp_path / "two.csv", "w") as fh:
        fh.write(",".join(frame.columns) + "\n" + ",".join(units) + "\n" + ",".join(["x"] * len(units)) + "\n")
        frame.to_csv(fh, header=False, index=False)
    with pytest.raises(DataError, match=f"data row 1: '{re.escape(time_unit)}' is not a number"):
        am.read_recording(tmp_path / "two.csv")


def test_a_plain_time_column_in_milliseconds_is_named_and_fs_settles_it(tmp_path, rec):
    """A column called 'time' holding milliseconds read as seconds gave 0.06 Hz and a
    failure deep in the spectra ('nperseg ... got 1'): refused at reading with the fix; a
    --fs 1,000 times the file's rate says the column is in ms and is taken."""
    path = am.write_recording_csv(rec, tmp_path / "r.csv")
    frame = pd.read_csv(path, comment="#")
    frame["time"] *= 1e3
    frame.to_csv(tmp_path / "ms.csv", index=False)
    with pytest.raises(DataError, match="steps by 16.67 s .*'time_ms'.*--fs"):
        am.read_recording(tmp_path / "ms.csv")
    back = am.read_recording(tmp_path / "ms.csv", fs=60.0)
    assert back.fs == 60.0 and back.sensors == rec.sensors
    np.testing.assert_allclose(back.response, rec.response, rtol=1e-8)
    frame["time"] *= 1e3  # microseconds
    frame.to_csv(tmp_path / "us.csv", index=False)
    assert am.read_recording(tmp_path / "us.csv", fs=60.0).fs == 60.0
    with pytest.raises(DataError, match="fs = 6e-05 Hz but fs = 61 Hz was passed"):
        am.read_recording(tmp_path / "us.csv", fs=61.0)


def test_a_mat_struct_is_read_field_by_field(tmp_path, rec):
    """A record saved as one MATLAB struct read as 'no numeric channels found'. Its fields
    are the variables; a field named as a top-level variable keeps the struct's prefix."""
    fields = {"time": rec.time, "base": rec.base, **{s: rec.response[:, k] for k, s in enumerate(rec.sensors)}}
    scipy.io.savemat(tmp_path / "s.mat", {"data": fields})
    back = am.read_recording(tmp_path / "s.mat")
    assert back.fs == pytest.approx(60.0, rel=1e-9) and back.sensors == rec.sensors
    np.testing.assert_array_equal(back.response, rec.response)
    trials = np.empty((2,), dtype=[("x", "O")])  # a struct array: which element is the record?
    trials[0]["x"], trials[1]["x"] = 3 * rec.base, 4 * rec.base
    scipy.io.savemat(tmp_path / "c.mat", {"data": fields, "head": 2 * rec.response[:, 0], "trials": trials})
    both = am.read_recording(tmp_path / "c.mat")
    assert set(both.sensors) == {*rec.sensors, "data.head"}
    np.testing.assert_array_equal(both.response[:, both.sensors.index("head")], 2 * rec.response[:, 0])


def test_csv_output_selection(tmp_path):
    p = _write(tmp_path, "r.csv", "time,base,a,b,c\n0,1,2,3,4\n0.5,2,3,4,5\n1.0,0,1,1,1\n")
    r = am.read_recording(p, outputs=["c", "a"])
    assert r.sensors == ("c", "a") and r.fs == 2.0
    with pytest.raises(DataError, match="unknown output"):
        am.read_recording(p, outputs=["z"])


@pytest.mark.parametrize(
    "text, kwargs, message",
    [
        ("time,plat,a\n0,1,2\n1,2,3\n2,0,1\n", {}, "input channel 'base' not found.*--input"),
        ("base,a\n1,2\n2,3\n", {}, "fs=.*--fs"),
        ("time,base,a\n0,1,2\n1,2,x3\n2,0,1\n", {}, "column 'a', data row 2: 'x3' is not a number"),
        ("time,base,a\n0,1,2\n1,2,3\n2.5,0,1\n3.5,1,1\n", {}, "not uniformly spaced"),
        ("time,base,a\n0,1,2\n1,2,3\n2.5,0,1\n3.5,1,1\n", {}, "from data row 2 to 3 it steps 1.5 s"),
        # rows out of order: once bridged as if samples were missing, then "steps 0 s"
        ("time,base,a\n0,1,2\n4,2,3\n1,0,1\n2,1,1\n3,1,2\n", {}, "not increase from data row 2 to 3 .4 s, then 1 s"),
        ("time,base,a\n0,1,2\n1,2,3\n1,0,1\n2,1,1\n", {}, "does not increase from data row 2 to 3 .*repeated"),
        ("time,base,a\n0,1,2\n1,2,3\n6,0,1\n7,1,1\n8,0,2\n", {}, "4 samples missing after row 1 .*cut the record"),
        ("time,base,a\n0,1,2\n1,2,\n2,0,1\n", {}, "data row 2 is empty"),
        ("time,base,a\n0,1,2\n1,2,nan\n2,0,1\n", {}, "channel 'a' has 1 NaN"),
        ("time,base,a\n0,1,2\n1,2,3\n2,0,1\n", {"fs": 50.0}, "fs = 1 Hz but fs = 50 Hz"),
        ("time,base,a\n", {}, "no data rows"),
        ("", {}, "empty"),
        ("time,base,a\n0,1,2\n1,1,3\n2,1,1\n", {}, "constant"),
        ("time,base\n0,1\n1,2\n2,0\n", {}, "no outputs"),
        # a channel exported twice under one name: once read as 'a' and 'a.1' in silence
        ("time,base,a,a\n0,1,2,2\n1,2,3,3\n2,0,1,1\n", {}, "'a' .columns 3, 4."),
        ("time,base,a,b,a,b\n0,1,2,2,2,2\n1,2,3,3,3,3\n", {}, "'a' .columns 3, 5.; 'b' .columns 4, 6."),
        # a second 'CSV UTF-8' export appended to the first: its byte-order mark inside the file
        ("time,base,a\n0,1,2\n1,2,3\n\ufefftime,base,a\n2,0,1\n", {}, "line 4 holds a byte-order mark"),
    ],
)
def test_bad_csv_gets_a_clear_error(tmp_path, text, kwargs, message):
    p = _write(tmp_path, "bad.csv", text)
    with pytest.raises(DataError, match=message):
        am.read_recording(p, **kwargs)


@pytest.mark.parametrize("gz", [False, True])
def test_a_spreadsheets_byte_order_mark_before_comment_lines_is_read_through(tmp_path, rec, gz):
    """'CSV UTF-8' from a spreadsheet starts with a byte-order mark, which hid the first '#': the
    comment line was refused as a metadata line that needs a '#' it already has."""
    plain = am.write_recording_csv(rec, tmp_path / "plain.csv").read_bytes()
    assert plain.startswith(b"#")
    p = tmp_path / ("bom.csv.gz" if gz else "bom.csv")
    p.write_bytes(gzip.compress(b"\xef\xbb\xbf" + plain) if gz else b"\xef\xbb\xbf" + plain)
    back = am.read_recording(p)
    assert back.subject == "S3" and back.mass_kg == pytest.approx(76.96) and back.sensors == rec.sensors
    np.testing.assert_allclose(back.response, rec.response, rtol=1e-8)


@pytest.mark.parametrize("lost", [1, 2, 3])
def test_a_dropped_row_is_bridged_and_named(tmp_path, fixtures_dir, lost):
    """A logger that dropped 1-3 rows from row 3000 of the supine ride: the time column steps
    that many samples more there. The rows are filled by linear interpolation in every
    channel, every other sample is the file's, and the gap is a ``dropped_packet`` warning
    with its time."""
    from armaxmodal.prepare.preparation import prepare

    frame = pd.read_csv(fixtures_dir / "supine_random.csv", comment="#")
    path = tmp_path / "gap.csv"
    gone = list(range(3000, 3000 + lost))
    frame.drop(index=gone).to_csv(path, index=False)
    rec, full = am.read_recording(path), am.read_recording(fixtures_dir / "supine_random.csv")
    assert rec.n_samples == full.n_samples and rec.fs == pytest.approx(full.fs, rel=1e-9)
    kept = np.ones(full.n_samples, bool)
    kept[gone] = False
    np.testing.assert_array_equal(rec.response[kept], full.response[kept])
    np.testing.assert_array_equal(rec.base[kept], full.base[kept])
    after = 3000 + lost
    step = (full.response[after] - full.response[2999]) / (lost + 1)
    line = full.response[2999] + np.outer(np.arange(1, lost + 1), step)
    np.testing.assert_allclose(rec.response[gone], line, rtol=1e-12, atol=1e-12)
    (note,) = rec.meta["read_warnings"]
    assert (note.code, note.value, note.channels) == ("dropped_packet", float(lost), ("base", *full.sensors))
    assert f"{lost} sample(s) missing at 49.983 s" in note.message
    assert "dropped_packet" in [w.code for w in prepare(rec).warnings]
    assert am.read_recording(path, outputs=["chest"]).meta["read_warnings"][0].channels == ("base", "chest")


@pytest.mark.parametrize("given, message", [(["a.csv", "b.csv"], "reads one file; got 2.*read_xsens"),
                                            (42, "expected a file path, got int")])
def test_not_a_path_gets_a_typed_error(given, message):
    with pytest.raises(DataError, match=message):
        am.read_recording(given)


def test_missing_file():
    with pytest.raises(FileNotFoundError):
        am.read_recording("/nonexistent/file.csv")


def test_mismatched_lengths_in_arrays():
    with pytest.raises(DataError, match="common length"):
        am.Recording(60.0, np.arange(10.0), np.ones((9, 2)))


def test_input_file_is_never_modified(tmp_path, rec):
    path = am.write_recording_csv(rec, tmp_path / "r.csv")
    before = hashlib.sha256(path.read_bytes()).hexdigest()
    am.read_recording(path)
    assert hashlib.sha256(path.read_bytes()).hexdigest() == before


def test_failed_write_leaves_nothing(tmp_path, rec):
    from armaxmodal.io.write import atomic_write

    def broken(tmp):
        with open(tmp, "w") as fh:
            fh.write("partial")
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError):
        atomic_write(tmp_path / "out.csv", broken)
    assert list(tmp_path.iterdir()) == []


def test_mat_round_trip_with_matrix_channels(tmp_path):
    n = 500
    rng = np.random.default_rng(0)
    force = rng.standard_normal(n)
    acc = rng.standard_normal((3, n))
    p = tmp_path / "gvt.mat"
    scipy.io.savemat(p, {"Fs": 400.0, "Force": force[None, :], "Acceleration": acc})
    r = am.read_recording(p, input="Force")
    assert r.fs == 400.0 and r.sensors == ("Acceleration_1", "Acceleration_2", "Acceleration_3")
    np.testing.assert_array_equal(r.response, acc.T)


def test_mat_with_named_response(tmp_path):
    p = tmp_path / "r.mat"
    rng = np.random.default_rng(1)
    scipy.io.savemat(
        p,
        {
            "time": np.arange(100) / 60.0,
            "base": rng.standard_normal(100),
            "response": rng.standard_normal((100, 2)),
            "sensors": np.array(["head", "legs"], dtype=object),
        },
    )
    r = am.read_recording(p)
    assert r.sensors == ("head", "legs") and r.fs == pytest.approx(60.0)


def test_corrupt_and_v73_mat_files(tmp_path):
    p = tmp_path / "corrupt.mat"
    p.write_bytes(b"MATLAB 5.0 MAT-file" + b"\x00" * 20)
    with pytest.raises(DataError, match="not a readable MAT"):
        am.read_recording(p, fs=1.0)
    header = b"MATLAB 7.3 MAT-file, Platform: GLNXA64".ljust(116, b" ") + b"\x00" * 8 + b"\x00\x02IM"
    p73 = tmp_path / "v73.mat"
    p73.write_bytes(header + b"\x00" * 512)
    with pytest.raises(DataError, match="v7.3"):
        am.read_recording(p73, fs=1.0)


def test_uff_round_trip(tmp_path, rec):
    path = am.write_recording_uff(rec, tmp_path / "r.uff")
    back = am.read_recording(path)
    # UFF 58 stores the sample step as E13.5 (six significant digits).
    assert back.fs == pytest.approx(60.0, rel=1e-5)
    assert back.sensors == rec.sensors
    np.testing.assert_allclose(back.response, rec.response, rtol=1e-6)


def test_corrupt_uff(tmp_path):
    p = tmp_path / "bad.uff"
    p.write_text("    -1\n    58\nthis is not a data set\n")
    with pytest.raises(DataError, match="UFF"):
        am.read_recording(p, fs=1.0)


def test_real_f16_mat_file(realdata_dir):
    r = am.read_recording(
        realdata_dir / "f16_gvt" / "F16Data_FullMSine_Level1.mat",
        input="Force",
        outputs=["Acceleration_1", "Acceleration_2", "Acceleration_3"],
    )
    assert r.fs == 400.0 and r.n_samples == 73728


def test_real_shake_table_csv_needs_its_header_skipped(realdata_dir):
    """Xsens exports carry 7 header lines; reading them raw must fail clearly, not crash."""
    with pytest.raises(DataError):
        am.read_recording(realdata_dir / "mini_shake_table_imu" / "flex3" / "northridge__g.csv.gz")


def test_json_is_strict_nan_and_infinity_become_null(tmp_path):
    """Strict parsers reject bare NaN: the writer turns every non-finite number into null."""
    import json

    from armaxmodal.io.write import write_json

    path = write_json(
        {"a": float("nan"), "b": np.array([1.5, np.inf]), "c": [np.float64(-np.inf), 2]}, tmp_path / "x.json"
    )
    data = json.loads(path.read_text(), parse_constant=lambda c: pytest.fail(f"bare {c} written"))
    assert data == {"a": None, "b": [1.5, None], "c": [None, 2]}


def test_an_all_numeric_csv_reads_the_same_doubles_as_the_cell_by_cell_path(fixtures_dir, tmp_path):
    """The C parser's fast path against the text path that checks every cell, on a fixture
    and on awkward but valid numbers (exponents, integers, signs, spaces after commas)."""
    import pandas as pd

    from armaxmodal.io.csv_format import _text_channels, read_csv_file

    awkward = tmp_path / "awkward.csv"
    awkward.write_text("time, base, a\n0, 1e-3, -2\n0.01, -4.5E+2, 3\n0.02, 0.1, +7.25\n0.03, 12, 1e300\n")
    for path in (fixtures_dir / "supine_random.csv", awkward):
        fast, _, _ = read_csv_file(path)
        text = pd.read_csv(path, comment="#", skipinitialspace=True, dtype=str, keep_default_na=False)
        text.columns = [c.strip() for c in text.columns]
        slow = _text_channels(text, path)
        slow.pop("time")
        assert fast.keys() == slow.keys()
        for name in fast:
            np.testing.assert_array_equal(fast[name], slow[name])


def _ride_with_gap(fixtures_dir, tmp_path, rows, name="gap.csv", column=2):
    """The bundled ride with the cells of ``column`` (head) emptied on the data rows ``rows``."""
    lines = (fixtures_dir / "supine_random.csv").read_text().splitlines()
    header = next(i for i, line in enumerate(lines) if line.startswith("time,"))
    out = lines[: header + 1]
    for i, line in enumerate(lines[header + 1 :]):
        cells = line.split(",")
        if i in rows:
            cells[column] = ""
        out.append(",".join(cells))
    path = tmp_path / name
    path.write_text("\n".join(out) + "\n")
    return path


def test_a_gap_is_refused_unless_asked_to_fill_and_then_filled_and_named(fixtures_dir, tmp_path):
    path = _ride_with_gap(fixtures_dir, tmp_path, range(3000, 3002))  # 2 samples, 33 ms at 60 Hz
    with pytest.raises(DataError, match=r"data row 3001 is empty .*--fill-gaps SECONDS"):
        am.read_recording(path)
    whole = am.read_recording(fixtures_dir / "supine_random.csv")
    filled = am.read_recording(path, fill_gaps=0.04)
    (note,) = filled.meta["read_warnings"]
    assert note.code == "gap_filled" and note.channels == ("head",) and "data rows 3001-3002" in note.message
    head = list(whole.sensors).index("head")
    expected = np.interp([3000, 3001], [2999, 3002], whole.response[[2999, 3002], head])
    np.testing.assert_allclose(filled.response[3000:3002, head], expected)
    untouched = np.ones(whole.n_samples, bool)
    untouched[3000:3002] = False
    np.testing.assert_array_equal(filled.response[untouched], whole.response[untouched])


@pytest.mark.parametrize("rows, limit, message", [
    (range(3000, 3003), 0.04, r"data rows 3001-3003: 3 missing samples, more than the 2 samples --fill-gaps allows"),
    (range(0, 2), 0.1, r"data rows 1-2: missing at the start"),
])  # fmt: skip
def test_a_gap_longer_than_asked_or_at_an_end_is_refused_with_its_rows(fixtures_dir, tmp_path, rows, limit, message):
    with pytest.raises(DataError, match=message):
        am.read_recording(_ride_with_gap(fixtures_dir, tmp_path, rows), fill_gaps=limit)


def test_fill_gaps_bridges_more_dropped_rows_than_the_default(tmp_path):
    text = "time,base,a\n" + "".join(f"{t},{np.sin(t)},{np.cos(t)}\n" for t in [*range(0, 5), *range(10, 40)])
    path = _write(tmp_path, "dropped.csv", text)
    with pytest.raises(DataError, match="5 samples missing"):
        am.read_recording(path)
    rec = am.read_recording(path, fill_gaps=5.0)
    assert rec.n_samples == 40 and [w.code for w in rec.meta["read_warnings"]] == ["dropped_packet"]
    with pytest.raises(DataError, match="fill_gaps: expected the longest gap"):
        am.read_recording(path, fill_gaps=-1.0)


def test_a_spreadsheets_empty_trailing_columns_are_left_out_with_a_note(tmp_path, fixtures_dir):
    """``,,,,`` after every line (a spreadsheet's empty columns): the file reads as without them,
    with an ``empty_columns_dropped`` note; an unnamed column that holds a value is refused by
    its number, and a name given twice is still refused by name."""
    src = fixtures_dir / "supine_random.csv"
    lines = src.read_text().splitlines()
    padded = [ln if ln.startswith("#") else ln + ",,,," for ln in lines]
    path = tmp_path / "padded.csv"
    path.write_text("\n".join(padded) + "\n")
    rec, plain = am.read_recording(path), am.read_recording(src)
    assert rec.sensors == plain.sensors and rec.fs == plain.fs
    np.testing.assert_array_equal(rec.response, plain.response)
    np.testing.assert_array_equal(rec.base, plain.base)
    (note,) = rec.meta["read_warnings"]
    assert note.code == "empty_columns_dropped" and note.value == 4.0 and "columns 7-10" in note.message
    k = next(i for i, ln in enumerate(padded) if not ln.startswith("#")) + 30
    padded[k] = padded[k][:-2] + "7,"
    path.write_text("\n".join(padded) + "\n")
    with pytest.raises(DataError, match="column 8 has no name in the header but holds data \\(data row 30: .7.\\)"):
        am.read_recording(path)
    header = next(i for i, ln in enumerate(lines) if not ln.startswith("#"))
    twice = [*lines[:header], lines[header].replace("legs", "head"), *lines[header + 1 :]]
    path.write_text("\n".join(ln if ln.startswith("#") else ln + ",," for ln in twice) + "\n")
    with pytest.raises(DataError, match="more than once: 'head' \\(columns 3, 6\\)"):
        am.read_recording(path)


@pytest.mark.parametrize("decimals", [4, 3])
def test_a_time_column_rounded_to_its_printed_decimals_is_read_at_its_spans_rate(tmp_path, fixtures_dir, decimals):
    """60 Hz written with 4 (3) decimals steps 0.0166 and 0.0167 s (0.016 and 0.017): not a gap.
    Read at the rate of the whole span, with a ``time_rounded`` note; real jitter of a millisecond,
    printed the same way, is still refused, and a dropped row still bridged and named."""
    frame = pd.read_csv(fixtures_dir / "supine_random.csv", comment="#")
    full = am.read_recording(fixtures_dir / "supine_random.csv")
    rounded = frame.assign(time=frame.time.round(decimals))
    path = tmp_path / "rounded.csv"
    rounded.to_csv(path, index=False)
    rec = am.read_recording(path)
    span = rounded.time.iloc[-1] - rounded.time.iloc[0]
    assert rec.fs == pytest.approx((len(frame) - 1) / span, rel=1e-9)
    assert rec.fs == pytest.approx(60.0, abs=10.0 ** -decimals * 60**2 / span)  # the span's rounding, no more
    np.testing.assert_array_equal(rec.response, full.response)
    (note,) = rec.meta["read_warnings"]
    assert note.code == "time_rounded" and f"printed to 1e-0{decimals} s" in note.message
    assert note.value <= 10.0**-decimals
    jitter = np.random.default_rng(0).uniform(-1e-3, 1e-3, len(frame))
    frame.assign(time=(frame.time + jitter).round(decimals)).to_csv(path, index=False)
    with pytest.raises(DataError, match="not uniformly spaced"):
        am.read_recording(path)
    rounded.drop(index=[3000]).to_csv(path, index=False)
    codes = [w.code for w in am.read_recording(path).meta["read_warnings"]]
    assert "dropped_packet" in codes
    # the same column in milliseconds, printed to 3 decimals fewer: its digit is the same in seconds
    in_ms = frame.assign(time=(frame.time * 1000).round(decimals - 3)).rename(columns={"time": "time_ms"})
    in_ms.to_csv(path, index=False)
    (note,) = am.read_recording(path).meta["read_warnings"]
    assert note.code == "time_rounded" and f"printed to 1e-0{decimals} s" in note.message


def test_a_target_that_is_no_regular_file_is_written_into_not_renamed_over(tmp_path):
    """``--json /dev/null`` run as root renamed a regular file over the device (the machine's
    ``/dev/null`` became a file, and apt could no longer check its packages' signatures). A named
    pipe stands in for the device: it stays a pipe, its reader gets the bytes, and nothing is
    staged beside it."""
    import os
    import stat
    import threading

    from armaxmodal.io.write import atomic_write, write_all

    pipe, regular = tmp_path / "pipe", tmp_path / "modes.json"
    os.mkfifo(pipe)
    for write in (lambda: write_all([(regular, lambda tmp: open(tmp, "w").write("{}")),
                                     (pipe, lambda tmp: open(tmp, "w").write('{"ok": true}'))]),
                  lambda: atomic_write(pipe, lambda tmp: open(tmp, "w").write('{"ok": true}'))):  # fmt: skip
        got = []
        reader = threading.Thread(target=lambda got=got: got.append(pipe.read_bytes()), daemon=True)
        reader.start()
        write()
        reader.join(timeout=20)
        assert stat.S_ISFIFO(os.stat(pipe).st_mode)
        assert got == [b'{"ok": true}']
        assert sorted(p.name for p in tmp_path.iterdir()) == ["modes.json", "pipe"]
        assert regular.read_text() == "{}"
