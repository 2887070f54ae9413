"""Studies: Table 3.3 against the synthetic study's truth, parallel and dask runs equal to the
serial one, resume from the cache, bad rows reported while the rest go on, the HTML report."""

import hashlib
import json
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from armaxmodal.cli import main
from armaxmodal.exceptions import DataError
from armaxmodal.study import StudySettings, make_study, match_modes, run_study, write_study
from armaxmodal.study.run import CACHE_FOLDER
from tests.conftest import open_in_headless_chromium

SETTINGS = StudySettings(lump=("legs", "feet"))
#: for the tests of the study's plumbing (schedulers, cache, bad rows), where only equal tables
#: matter: a short sweep of orders, a third of the default's time
PLUMBING = StudySettings(orders=(2, 12), lump=("legs", "feet"))


@pytest.fixture(scope="module")
def study_dir(tmp_path_factory):
    folder = tmp_path_factory.mktemp("study")
    truth = make_study(folder, 5, feet_subjects=(1, 2), separate_feet=(2,), seed=7)
    return folder, truth


@pytest.fixture(scope="module")
def finished(study_dir, tmp_path_factory):
    folder, truth = study_dir
    out = tmp_path_factory.mktemp("out")
    study = run_study(folder / "manifest.csv", out, SETTINGS, jobs=2)
    return study, out, truth


def test_table_3_3_matches_the_truth_it_was_built_from(finished):
    study, _, truth = finished
    assert not study.failures
    exact = {(s["subject"], m["mode"]): m for s in truth["subjects"] for m in s["modes"]}
    found = study.tables.subjects
    # every subject's own modes (Table 3.3 rows) against its exact modes
    err_f = [abs(r.freq_hz / exact[(r.subject, r.mode)]["freq_hz"] - 1) for r in found.itertuples()]
    err_z = [abs(r.damping / exact[(r.subject, r.mode)]["damping"] - 1) for r in found.itertuples()]
    # sweeps reach 20 Hz only: modes 3-4 of a stiff subject are partly excited. On one of the
    # ten recordings they come out as 16.34 and 16.85 Hz for 14.81 and 17.66 Hz (before the
    # selection by the modal-model check: merged into one, 16.34 Hz, the other missed); 35 of
    # the 40 rows sit within 3 %, most within a few per mil
    assert np.median(err_f) < 0.01 and np.mean(np.array(err_f) < 0.03) >= 0.85 and max(err_f) < 0.11
    assert np.median(err_z) < 0.08 and np.mean(np.array(err_z) < 0.2) >= 0.9
    assert len(found) >= 0.8 * 5 * 4 * 2  # at most a fifth of subject-ride-modes missed
    # Average and SD rows: the mean of the rows they summarise, and against the truth over the
    # same subjects (within 2 %, but 4 % and no SD check for the sweep's mode 3: one of its five
    # subjects gives 16.34 Hz for 14.81, the partly excited modes 3-4 above; before the
    # selection by the check that subject's mode 3 was missing from the row instead)
    for row in study.tables.summary.itertuples():
        rows = found[(found.ride == row.ride) & (found["mode"] == row.mode)]
        f = np.array([exact[(s, row.mode)]["freq_hz"] for s in rows.subject])
        assert row.n == len(rows)
        assert row.freq_hz_mean == pytest.approx(rows.freq_hz.mean(), rel=1e-9)
        partly_excited = row.ride == "sweep" and row.mode == 3
        assert row.freq_hz_mean == pytest.approx(f.mean(), rel=0.04 if partly_excited else 0.02)
        if row.n >= 3 and not partly_excited:
            assert row.freq_hz_sd == pytest.approx(f.std(ddof=1), abs=0.5 * f.std(ddof=1) + 0.05)


def test_lump_verdicts_follow_how_each_subject_was_built(finished):
    study, _, truth = finished
    built = {s["subject"]: s["feet"] for s in truth["subjects"]}
    verdicts = {(r["subject"], r["ride"]): r["lump"]["verdict"] for r in study.recordings if r["lump"]}
    assert set(s for s, _ in verdicts) == {s for s, f in built.items() if f}
    for (subject, _), verdict in verdicts.items():
        assert verdict == ("separate" if built[subject] == "separate" else "lump")
    assert "feet" not in study.sensors  # on 2 of 5 recordings: used by the lump check only


def test_outputs_follow_the_contract_and_are_strict(finished, tmp_path):
    study, _, _ = finished
    written = write_study(study, tmp_path)
    names = {p.name for p in written}
    assert {"summary.csv", "modes.csv", "study.json", "report.html", "shapes_sweep.png", "lump.csv"} <= names
    summary = pd.read_csv(tmp_path / "summary.csv")
    assert list(summary.columns[:7]) == [
        "ride",
        "mode",
        "freq_hz_mean",
        "freq_hz_sd",
        "damping_mean",
        "damping_sd",
        "n",
    ]
    modes = pd.read_csv(tmp_path / "modes.csv")
    assert list(modes.columns[:7]) == ["file", "subject", "ride", "mode", "rank", "freq_hz", "damping"]
    data = json.loads((tmp_path / "study.json").read_text(), parse_constant=lambda c: pytest.fail(f"bare {c}"))
    assert {"settings", "recordings", "failures", "summary"} <= set(data)
    assert data["settings"]["lump"] == ["legs", "feet"] and len(data["recordings"]) == 10


def _small_manifest(study_dir, tmp_path, rows=3) -> Path:
    folder, _ = study_dir
    manifest = pd.read_csv(folder / "manifest.csv").iloc[:rows]
    manifest["file"] = [str(folder / f) for f in manifest.file]
    path = tmp_path / "small.csv"
    manifest.to_csv(path, index=False)
    return path


def test_serial_parallel_and_dask_give_identical_tables(study_dir, tmp_path):
    distributed = pytest.importorskip("distributed")
    manifest = _small_manifest(study_dir, tmp_path, rows=2)  # two rows: one for each worker
    serial = run_study(manifest, tmp_path / "serial", PLUMBING, jobs=1)
    parallel = run_study(manifest, tmp_path / "parallel", PLUMBING, jobs=2)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cl:
        on_dask = run_study(manifest, tmp_path / "dask", PLUMBING, scheduler=cl.scheduler_address)
    for other in (parallel, on_dask):
        pd.testing.assert_frame_equal(serial.tables.modes, other.tables.modes)
        pd.testing.assert_frame_equal(serial.tables.summary, other.tables.summary)
        strip = [{k: v for k, v in r.items() if k != "seconds"} for r in serial.recordings]
        assert strip == [{k: v for k, v in r.items() if k != "seconds"} for r in other.recordings]


def test_an_interrupted_study_resumes_from_its_cache(study_dir, tmp_path):
    manifest = _small_manifest(study_dir, tmp_path)
    first = run_study(manifest, tmp_path / "out", PLUMBING, jobs=1)
    cached = sorted((tmp_path / "out" / CACHE_FOLDER).glob("*.json"))
    assert len(cached) == 3 and first.reused == 0
    cached[0].unlink()  # as if the run had died before that recording finished
    cached[1].write_text('{"half": ')  # or while writing it
    again = run_study(manifest, tmp_path / "out", PLUMBING, jobs=1)
    assert again.reused == 1
    pd.testing.assert_frame_equal(first.tables.modes, again.tables.modes)
    # other settings are other results: nothing reused (the first row, whose cache holds the first settings)
    other = run_study(_small_manifest(study_dir, tmp_path, rows=1), tmp_path / "out", StudySettings(orders=(2, 8)),
                      jobs=1)  # fmt: skip
    assert other.reused == 0 and len(other.recordings) == 1


def test_bad_rows_are_reported_and_the_rest_go_on(study_dir, tmp_path):
    folder, _ = study_dir
    good = pd.read_csv(folder / "manifest.csv").iloc[:2]
    rows = [dict(r, file=str(folder / r["file"])) for r in good.to_dict("records")]
    (tmp_path / "corrupt.csv").write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00binary")
    renamed = pd.read_csv(folder / rows[0]["file"], comment="#").rename(columns={"head": "kopf", "chest": "brust"})
    renamed.to_csv(tmp_path / "renamed.csv", index=False)
    rows += [
        {"file": "missing.csv", "subject": "X1", "ride": "sweep"},
        dict(rows[0]),  # the same row twice
        {"file": "corrupt.csv", "subject": "X2", "ride": "sweep"},
        {"file": "renamed.csv", "subject": "X3", "ride": "sweep"},
        {"file": rows[1]["file"], "subject": "X4", "ride": "random", "mass_kg": "heavy"},
    ]
    manifest = tmp_path / "m.csv"
    pd.DataFrame(rows).to_csv(manifest, index=False)
    before = hashlib.sha256(manifest.read_bytes()).hexdigest()
    out = tmp_path / "out"
    assert main(["study", str(manifest), "--out", str(out), "--jobs", "1", "--quiet", "--orders", "2:12"]) == 0
    assert hashlib.sha256(manifest.read_bytes()).hexdigest() == before
    data = json.loads((out / "study.json").read_text())
    reasons = {f["file"]: f["reason"] for f in data["failures"]}
    assert "file not found" in reasons["missing.csv"]
    assert "duplicate of manifest row 1" in reasons[rows[0]["file"]]
    assert "unreadable" in reasons["corrupt.csv"]
    assert "lacks sensor(s) ['head', 'chest']" in reasons["renamed.csv"]
    assert "not a number" in reasons[rows[1]["file"]]
    assert len(data["recordings"]) == 2 and (out / "report.html").is_file()


def test_study_refuses_bad_arguments_before_any_work(study_dir, tmp_path):
    folder, _ = study_dir
    (tmp_path / "afile").write_text("x")
    with pytest.raises(DataError, match="is a file"):
        run_and_raise(["study", str(folder), "--out", str(tmp_path / "afile")])
    with pytest.raises(DataError, match="write into the study's input"):
        run_and_raise(["study", str(folder), "--out", str(folder)])
    with pytest.raises(DataError, match="two different sensor names"):
        run_and_raise(["study", str(folder), "--out", str(tmp_path / "o"), "--lump", "legs"])
    with pytest.raises(DataError, match="'file' column"):
        (tmp_path / "bad.csv").write_text("name,subject\na.csv,S1\n")
        run_and_raise(["study", str(tmp_path / "bad.csv"), "--out", str(tmp_path / "o")])
    assert not (tmp_path / "o").exists()


def run_and_raise(argv):
    from armaxmodal.cli import build_parser

    args = build_parser().parse_args(argv + ["--quiet"])
    return args.func(args)


def test_mode_matching_numbers_modes_across_recordings():
    ref, labels = match_modes(
        [
            np.array([5.0, 8.0, 14.0]),
            np.array([5.2, 8.1, 13.8]),
            np.array([5.1, 9.9, 14.2]),
            np.array([5.0, 14.1]),
            np.array([5.1, 8.2, 11.0, 14.0]),
        ]
    )
    assert ref == pytest.approx([5.1, 8.1, 14.0])
    assert labels[3].tolist() == [1, 3]  # the missing mode 2 leaves a gap, not a shift
    assert labels[4].tolist() == [1, 2, 0, 3]  # an extra mode matches nothing
    assert labels[2].tolist() == [1, 2, 3]  # 9.9 Hz is within 25 % of 8.1 Hz


def test_report_is_self_contained_and_renders_in_a_headless_browser(finished, tmp_path):
    study, _, _ = finished
    write_study(study, tmp_path)
    html = (tmp_path / "report.html").read_text()
    assert "http://" not in html and "https://" not in html  # nothing fetched
    n_img = html.count("<img alt='stabilisation")
    assert n_img == 10 and html.count("src='data:image/png;base64,") == n_img + 2  # + two shape figures
    dom, console_errors = open_in_headless_chromium(tmp_path / "report.html", tmp_path / "profile")
    assert 'data-figures="12/12"' in dom
    assert not console_errors


def test_average_subject_model_reproduces_the_mean_modes_and_scales_by_mass(finished):
    from armaxmodal.study.model import average_subject_models

    study, _, truth = finished
    models, scaled = average_subject_models(study)
    scaled = pd.DataFrame(scaled)
    for m in models:
        assert "reason" not in m, m.get("reason")
        mean = study.tables.summary[study.tables.summary.ride == m["ride"]].set_index("mode")
        fitted = pd.DataFrame(m["model_modes"]).set_index("mode")
        assert np.allclose(fitted.freq_hz, mean.freq_hz_mean, rtol=0.03)
        # Eq. 4.7: every subject's masses sum to its mass, and springs scale by the same ratio
        mine = scaled[scaled.ride == m["ride"]]
        for _, g in mine.groupby("subject"):
            masses = g[g.component.str.startswith("masses")].value.sum()
            assert masses == pytest.approx(g.mass_kg.iloc[0], rel=1e-9)
            alpha = g.mass_kg.iloc[0] / m["mass_kg"]
            k1 = g[g.component == "k1"].value.iloc[0]
            assert k1 == pytest.approx(alpha * m["components"]["k"][0], rel=1e-9)


def test_a_subject_without_mass_is_named_when_scaling_is_asked(study_dir, tmp_path):
    manifest = _small_manifest(study_dir, tmp_path)
    table = pd.read_csv(manifest)
    # Sub02 sweep: no mass in the manifest nor in the file's '# mass_kg:' line
    source = Path(table.loc[2, "file"])
    copy = tmp_path / source.name
    copy.write_text("".join(ln for ln in source.read_text().splitlines(True) if not ln.startswith("# mass_kg")))
    table.loc[2, ["file", "mass_kg"]] = [str(copy), None]
    table.to_csv(manifest, index=False)
    body = StudySettings(sensors=("head", "chest", "pelvis", "legs"), orders=PLUMBING.orders)
    study = run_study(manifest, tmp_path / "out", body, jobs=1, model=True)
    assert any("Sub02_sweep.csv: no mass_kg" in n for n in study.notes)
    assert [m.get("reason") for m in study.models] == [None] * len(study.models) and len(study.models) == 2
    scaled = pd.DataFrame(study.scaled)
    assert set(scaled.subject) == {"Sub01"} and not study.failures


def test_a_folder_study_takes_subjects_from_the_files_and_notes_a_mixed_rate(study_dir, tmp_path):
    from scipy.signal import resample_poly

    import armaxmodal as am
    from armaxmodal.io.write import write_recording_csv

    folder, _ = study_dir
    rides = tmp_path / "rides"
    rides.mkdir()
    shutil.copy(folder / "Sub01_random.csv", rides / "a.csv")
    r = am.read_recording(folder / "Sub02_random.csv")
    faster = am.Recording(100.0, resample_poly(r.base, 5, 3), resample_poly(r.response, 5, 3, axis=0), r.sensors,
                          subject=r.subject, mass_kg=r.mass_kg)  # fmt: skip
    write_recording_csv(faster, rides / "b.csv")
    study = run_study(rides, tmp_path / "out", PLUMBING, jobs=2)
    assert [r["subject"] for r in study.recordings] == ["Sub01", "Sub02"]
    assert any("mixed sample rates" in n and "b.csv (100 Hz)" in n for n in study.notes)
    assert not study.failures and study.recordings[1]["fs"] == 100.0
