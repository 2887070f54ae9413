"""One recording through the stabilise pipeline visits the preparation once and computes each
of its spectra once: every later stage reads what the record carries (Recording.welch)."""

import hashlib
import inspect
import sys
from contextlib import contextmanager
from dataclasses import replace

import numpy as np

import armaxmodal as am
from armaxmodal.modes.poles import disturbance_lines
from armaxmodal.prepare.preparation import prepare
from armaxmodal.spectra import welch_spectra


@contextmanager
def calls_of(func):
    """Every call of ``func`` in this thread while the block runs, as its arguments on entry: seen
    by a profile hook, so no module global is replaced and the code under test runs as shipped."""
    code, seen, before = inspect.unwrap(func).__code__, [], sys.getprofile()

    def hook(frame, event, arg):
        if event == "call" and frame.f_code is code:
            seen.append(dict(frame.f_locals))
        if before is not None:  # one hook per thread: an outer block's still sees its calls
            before(frame, event, arg)

    sys.setprofile(hook)
    try:
        yield seen
    finally:
        sys.setprofile(before)


def _digest(*arrays) -> str:
    return hashlib.sha1(b"".join(np.ascontiguousarray(a).tobytes() for a in arrays)).hexdigest()


def test_prepared_once_and_each_spectrum_computed_once(fixtures_dir):
    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    with calls_of(prepare) as preparations, calls_of(welch_spectra) as calls:
        selection = am.select_modes(am.stabilisation_diagram(rec, orders=range(4, 17, 2), n_jobs=1), n_jobs=1)
    assert selection.modes.shape[0] >= 3  # the pipeline ran to the end
    assert len(preparations) == 1 and preparations[0]["recording"] is rec
    spectra = [(_digest(c["u"], c["y"]), c["fs"], c["nperseg"]) for c in calls]
    assert len(spectra) >= 2  # the checks' and the selection's segment lengths
    assert len(set(spectra)) == len(spectra), "a record's spectra computed twice"


def test_the_diagrams_warnings_are_found_once_however_often_they_are_read(fixtures_dir):
    """A selection's quality, verdict and JSON each read the diagram's warnings; the disturbance
    lines behind them are found once per diagram, and a reader's list is its own copy."""
    rec = am.read_recording(fixtures_dir / "supine_random.csv")
    diagram = am.stabilisation_diagram(rec, orders=range(4, 13, 2), n_jobs=1)
    with calls_of(disturbance_lines) as found:
        selection = am.select_modes(diagram, n_jobs=1, segments=0)
        codes = [w.code for w in selection.warnings]
        selection.to_dict(), selection.quality, selection.verdict
    assert len(found) == 1 and [w.code for w in selection.warnings] == codes
    diagram.warnings.clear()
    assert [w.code for w in selection.warnings] == codes


def test_each_cut_of_the_record_is_transformed_once(bundled_diagram):
    """The refit, the count and the check's confirmation fit DFT lines of the same record, its two
    halves among them: each signal of each cut is transformed once (Recording.dft), however many
    stages fit its lines."""
    fresh = replace(bundled_diagram, recording=replace(bundled_diagram.recording))  # no DFT kept from another test
    with calls_of(np.fft.rfft) as calls:
        selection = am.select_modes(fresh, segments=0, n_jobs=1)
    assert selection.count is not None and selection.refinement is not None  # both fitted lines
    signals = [_digest(c["a"]) for c in calls]
    assert len(signals) >= 2 * 2  # the whole record and its halves, input and outputs
    assert len(set(signals)) == len(signals), "a cut of the record transformed twice"
