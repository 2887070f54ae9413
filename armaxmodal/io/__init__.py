"""Reading and writing recordings: CSV, MAT, UFF and Xsens DOT exports in; CSV, UFF and
strict JSON out, each written whole or not at all.

* :func:`~armaxmodal.read_recording` -- one file to a :class:`~armaxmodal.recording.Recording`.
* :func:`~armaxmodal.read_xsens` -- one Xsens DOT export per sensor, aligned on their clocks.
* :func:`~armaxmodal.write_recording_csv`, :func:`~armaxmodal.write_recording_uff`, :func:`write_json`.
"""

from armaxmodal.io.read import read_recording
from armaxmodal.io.write import write_json, write_recording_csv, write_recording_uff
from armaxmodal.io.xsens import read_xsens

__all__ = ["read_recording", "read_xsens", "write_json", "write_recording_csv", "write_recording_uff"]
