"""Studies: many subjects and rides through one stabilisation and selection, the thesis's
Chapter 3 tables and figures, and a self-contained HTML report.

* :func:`run_study` -- read a manifest or folder, analyse every recording in parallel (local
  processes or a dask.distributed cluster), resume from a per-recording cache.
* :func:`write_study` -- ``summary.csv``, ``modes.csv``, ``study.json``, figures and report,
  written whole or not at all.
* :func:`make_study` -- a synthetic study with known truth (15 subjects x 2 rides).
* :func:`track_modes` and :func:`write_track` -- many events of one structure: each mode followed
  across them, its trend with the shaking and the events that depart from it.
"""

from armaxmodal.study.job import StudySettings, analyse_recording
from armaxmodal.study.manifest import Entry, read_manifest
from armaxmodal.study.output import write_study
from armaxmodal.study.run import Study, run_study
from armaxmodal.study.synthetic import make_study
from armaxmodal.study.tables import StudyTables, build_tables, match_modes, summarise_subjects
from armaxmodal.study.track import Track, TrackSettings, Trend, fit_trend, match_tracks, track_modes
from armaxmodal.study.track_output import plot_track, write_track

__all__ = [
    "Entry",
    "Study",
    "StudySettings",
    "StudyTables",
    "analyse_recording",
    "build_tables",
    "make_study",
    "match_modes",
    "read_manifest",
    "run_study",
    "summarise_subjects",
    "Track",
    "TrackSettings",
    "Trend",
    "fit_trend",
    "match_tracks",
    "plot_track",
    "track_modes",
    "write_study",
    "write_track",
]
