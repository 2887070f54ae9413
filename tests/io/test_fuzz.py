"""Property-based fuzzing of the readers and validators (Hypothesis).

Whatever a file holds -- random bytes, a fixture cut anywhere, a CSV with cells, lines or
headers damaged as exports damage them, a MAT file of random variables, a UFF file cut short
-- reading it either gives a recording whose numbers are the file's own (finite, the
channels it names) or raises one of the package's typed errors. Never a traceback from
pandas, numpy, scipy or pyuff, never a silently changed number. Example counts are small
(the suite's time budget); ``HYPOTHESIS_PROFILE=long`` runs a thorough pass.
"""

from __future__ import annotations

import gzip
import io
import os

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import armaxmodal as am
from armaxmodal.exceptions import ArmaxModalError
from armaxmodal.io.write import write_recording_uff
from armaxmodal.prepare.preparation import check_band

settings.register_profile(
    "ci", max_examples=40, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
settings.register_profile("long", max_examples=2000, deadline=None, suppress_health_check=list(HealthCheck))
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

ROWS = 300  # a fixture's first rows: enough for a recording, small enough to read fast


@pytest.fixture(scope="module")
def small_csv(fixtures_dir) -> str:
    lines = (fixtures_dir / "supine_random.csv").read_text().splitlines()
    return "\n".join(lines[: 3 + ROWS]) + "\n"  # two comment lines, the header, ROWS samples


def _read(path, **options):
    """The reader's answer: a Recording, or the typed error it raised (anything else fails)."""
    try:
        return am.read_recording(path, **options)
    except ArmaxModalError as exc:
        assert str(exc).strip(), "a typed error must say what was wrong"
        return exc


def _sound(rec: am.Recording, max_samples: int) -> None:
    """A recording handed back is usable: finite samples, named channels, a positive rate."""
    assert np.isfinite(rec.fs) and rec.fs > 0
    assert np.all(np.isfinite(rec.base)) and np.all(np.isfinite(rec.response))
    assert rec.response.shape == (rec.n_samples, len(rec.sensors)) and 0 < rec.n_samples <= max_samples
    assert len(set(rec.sensors)) == len(rec.sensors) and rec.input_name not in rec.sensors


@given(data=st.binary(min_size=0, max_size=2000), suffix=st.sampled_from([".csv", ".mat", ".uff", ".csv.gz"]))
@example(data=b"", suffix=".mat")  # found by the long profile: scipy's MatReadError
@example(data=b"\x1f\x8b", suffix=".csv.gz")  # found by the long profile: gzip's EOFError
def test_random_bytes_give_a_typed_error(tmp_path, data, suffix):
    path = tmp_path / f"junk{suffix}"
    path.write_bytes(data)
    got = _read(path, fs=60.0)
    assert isinstance(got, ArmaxModalError) or _sound(got, 10**6) is None
    assert path.read_bytes() == data  # read, never modified


@given(cut=st.integers(min_value=0, max_value=20_000))
def test_a_csv_cut_anywhere_reads_its_whole_rows_or_is_refused(tmp_path, small_csv, cut):
    text = small_csv[: min(cut, len(small_csv))]
    path = tmp_path / "cut.csv"
    path.write_text(text)
    got = _read(path)
    if isinstance(got, am.Recording):
        _sound(got, ROWS)
        # the rows it kept are the file's own numbers, not shifted or re-parsed ones
        full = pd.read_csv(io.StringIO(small_csv), comment="#")
        np.testing.assert_allclose(got.base, full.base.to_numpy()[: got.n_samples], rtol=1e-12)
        np.testing.assert_allclose(got.response[:, 0], full["head"].to_numpy()[: got.n_samples], rtol=1e-12)


BAD_CELLS = ["", "NA", "nan", "abc", "1e999", "-inf", "1,5", "0x10", "—", "  ", "1.2.3", "TRUE"]


@st.composite
def damaged_csv(draw, text: str):
    lines = text.splitlines()
    body = list(range(3, len(lines)))
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(st.sampled_from(["cell", "drop_line", "dup_line", "header", "meta", "separator", "short_line"]))
        if kind == "cell":
            i = draw(st.sampled_from(body))
            cells = lines[i].split(",")
            cells[draw(st.integers(0, len(cells) - 1))] = draw(st.sampled_from(BAD_CELLS))
            lines[i] = ",".join(cells)
        elif kind == "drop_line":
            lines[draw(st.sampled_from(body))] = ""
        elif kind == "dup_line":
            i = draw(st.sampled_from(body))
            lines.insert(i, lines[i])
        elif kind == "header":
            names = lines[2].split(",")
            j = draw(st.integers(0, len(names) - 1))
            names[j] = draw(st.sampled_from(["", "head", "base", "time", "Unnamed: 0", "x'y", "legs"]))
            lines[2] = ",".join(names)
        elif kind == "meta":
            lines.insert(draw(st.integers(0, 3)), draw(st.sampled_from(["Device: DOT", "sep=,", "# mass_kg: abc", ""])))
        elif kind == "separator":
            i = draw(st.sampled_from(body))
            lines[i] = lines[i].replace(",", draw(st.sampled_from([";", "\t", " "])))
        else:
            i = draw(st.sampled_from(body))
            lines[i] = ",".join(lines[i].split(",")[:-1])
    return "\n".join(lines) + "\n"


@given(data=st.data())
def test_a_damaged_csv_is_read_as_written_or_refused(tmp_path, small_csv, data):
    text = data.draw(damaged_csv(small_csv))
    path = tmp_path / "damaged.csv"
    path.write_text(text)
    got = _read(path)
    if isinstance(got, am.Recording):
        _sound(got, 2 * ROWS)
    assert path.read_text() == text


@given(cut=st.integers(min_value=1, max_value=10**6), seed=st.integers(0, 3))
def test_a_uff_file_cut_short_is_refused_or_complete(tmp_path, cut, seed):
    rng = np.random.default_rng(seed)
    rec = am.Recording(50.0, rng.standard_normal(200), rng.standard_normal((200, 2)), ("a", "b"))
    full = write_recording_uff(rec, tmp_path / f"full{seed}.uff").read_bytes()
    path = tmp_path / "cut.uff"
    path.write_bytes(full[: cut % (len(full) + 1)])
    got = _read(path)
    if isinstance(got, am.Recording):  # only the whole file reads, with every channel
        assert got.sensors == ("a", "b") and got.n_samples == 200
        np.testing.assert_allclose(got.response, rec.response, rtol=1e-6)


mat_value = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.lists(st.floats(allow_nan=True, allow_infinity=True, width=32), min_size=0, max_size=300).map(np.array),
    st.integers(0, 3).map(lambda k: np.random.default_rng(k).standard_normal((150, 1 + k))),
    st.text(max_size=5),
)


@given(
    variables=st.dictionaries(
        st.sampled_from(["base", "fs", "Fs", "time", "head", "response", "sensors", "X", "Voltage", "u"]),
        mat_value,
        max_size=6,
    )
)
@example(variables={"base": 0.0})  # found: max() of an empty sequence
@example(variables={"time": np.array([0.0, np.inf, 0.0])})  # found: ZeroDivisionError
def test_a_mat_file_of_random_variables_gives_a_recording_or_a_typed_error(tmp_path, variables):
    from scipy.io import savemat

    path = tmp_path / "random.mat"
    savemat(path, variables)
    got = _read(path)
    if isinstance(got, am.Recording):
        _sound(got, 10**6)


@given(
    lo=st.one_of(st.floats(), st.text(max_size=3), st.none()),
    hi=st.one_of(st.floats(), st.text(max_size=3), st.none()),
    fs=st.floats(min_value=1.0, max_value=1e4),
)
def test_check_band_returns_an_ordered_band_below_nyquist_or_a_typed_error(lo, hi, fs):
    try:
        band = check_band((lo, hi), fs)
    except ArmaxModalError:
        return
    assert 0 <= band[0] < band[1] <= fs / 2


@given(
    n=st.integers(0, 50),
    k=st.integers(0, 3),
    fs=st.floats(allow_nan=True, allow_infinity=True),
    poison=st.sampled_from([None, np.nan, np.inf, 1e308]),
)
def test_recording_accepts_only_finite_consistent_samples(n, k, fs, poison):
    rng = np.random.default_rng(n)
    base, response = rng.standard_normal(n), rng.standard_normal((n, k))
    if poison is not None and n and k:
        response[n // 2, 0] = poison
    try:
        rec = am.Recording(fs, base, response, tuple(f"s{i}" for i in range(k)))
    except ArmaxModalError:
        return
    _sound(rec, 10**6)


def test_gzip_csv_reads_like_the_plain_file(tmp_path, small_csv):
    """The gzip path of the fuzzed reader, checked against the plain file once."""
    plain, packed = tmp_path / "r.csv", tmp_path / "r.csv.gz"
    plain.write_text(small_csv)
    packed.write_bytes(gzip.compress(small_csv.encode()))
    a, b = am.read_recording(plain), am.read_recording(packed)
    np.testing.assert_array_equal(a.response, b.response)
