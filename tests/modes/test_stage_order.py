"""One recording through the stabilise pipeline visits the preparation once and computes each
of its spectra once: every later stage reads what the record carries (Recording.welch)."""

import hashlib

import numpy as np

import armaxmodal as am
import armaxmodal.modes.diagram as diagram_module
import armaxmodal.recording as recording_module


def _digest(*arrays) -> str:
    return hashlib.sha1(b"".join(np.ascontiguousarray(a).tobytes() for a in arrays)).hexdigest()


def test_prepared_once_and_each_spectrum_computed_once(monkeypatch, fixtures_dir):
    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    preparations, spectra = [], []
    prepare, welch_spectra = diagram_module.prepare, recording_module.welch_spectra

    def counted_prepare(*args, **kwargs):
        preparations.append(args[0])
        return prepare(*args, **kwargs)

    def counted_welch(u, y, fs, nperseg):
        spectra.append((_digest(u, y), fs, nperseg))
        return welch_spectra(u, y, fs, nperseg)

    monkeypatch.setattr(diagram_module, "prepare", counted_prepare)
    monkeypatch.setattr(recording_module, "welch_spectra", counted_welch)
    selection = am.select_modes(am.stabilisation_diagram(rec, orders=range(4, 17, 2), n_jobs=1), n_jobs=1)
    assert selection.modes.shape[0] >= 3  # the pipeline ran to the end
    assert len(preparations) == 1
    assert len(spectra) >= 2  # the checks' and the selection's segment lengths
    assert len(set(spectra)) == len(spectra), "a record's spectra computed twice"


def test_the_diagrams_warnings_are_found_once_however_often_they_are_read(monkeypatch, fixtures_dir):
    """A selection's quality, verdict and JSON each read the diagram's warnings; the disturbance
    lines behind them are found once per diagram, and a reader's list is its own copy."""
    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    diagram = am.stabilisation_diagram(rec, orders=range(4, 13, 2), n_jobs=1)
    found, lines = [], diagram_module.disturbance_lines
    monkeypatch.setattr(diagram_module, "disturbance_lines", lambda *a, **k: found.append(1) or lines(*a, **k))
    selection = am.select_modes(diagram, n_jobs=1, segments=0)
    codes = [w.code for w in selection.warnings]
    selection.to_dict(), selection.quality, selection.verdict
    assert found == [1] and [w.code for w in selection.warnings] == codes
    diagram.warnings.clear()
    assert [w.code for w in selection.warnings] == codes
