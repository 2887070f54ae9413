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
