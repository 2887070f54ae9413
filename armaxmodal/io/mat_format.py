"""MATLAB files (v5-v7 by scipy, v7.3 refused with advice): channels as vectors or struct
fields, all of one length.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

from armaxmodal.exceptions import DataError
from armaxmodal.io.time_axis import fs_from_time, time_scale


# -- MAT ------------------------------------------------------------------------------
def read_mat_file(path: Path):
    import zlib

    import scipy.io
    from scipy.io.matlab import MatReadError

    try:
        data = scipy.io.loadmat(path, squeeze_me=False)
    except NotImplementedError as exc:
        raise DataError(
            f"{path.name}: MATLAB v7.3 (HDF5) files are not supported; save with save(..., '-v7') or export to CSV."
        ) from exc
    except (
        MatReadError,
        ValueError,
        TypeError,
        IndexError,
        KeyError,
        OSError,
        struct.error,
        EOFError,
        zlib.error,
        UnicodeDecodeError,
        OverflowError,
        MemoryError,
    ) as exc:  # what scipy raises on random bytes (tests/test_fuzz.py)
        raise DataError(f"{path.name}: not a readable MAT file ({type(exc).__name__}: {exc}).") from exc
    arrays = _struct_fields({k: v for k, v in data.items() if not k.startswith("__") and isinstance(v, np.ndarray)})
    numeric = {k: np.squeeze(v) for k, v in arrays.items() if v.dtype.kind in "fiu" and v.size > 0}
    file_fs = None
    for key in ("fs", "Fs", "FS"):
        if key in numeric and numeric[key].size == 1:
            file_fs = float(numeric.pop(key))
            break
    time_key = next((k for k in numeric if time_scale(k) is not None), None)
    if time_key is not None:
        t = numeric.pop(time_key).ravel().astype(float) * time_scale(time_key)
        t_fs, _ = fs_from_time(t, path)
        file_fs = file_fs if file_fs is not None else t_fs
    sensor_names = None
    if "sensors" in arrays and arrays["sensors"].dtype.kind in "OU":
        sensor_names = [str(np.squeeze(s)) for s in np.ravel(arrays["sensors"])]
    vectors = [v for v in numeric.values() if v.ndim == 1]
    matrices = [v for v in numeric.values() if v.ndim >= 2]
    n = max((v.size for v in vectors), default=max((max(v.shape) for v in matrices), default=0))
    channels: dict[str, np.ndarray] = {}
    for key, v in numeric.items():
        v = v.astype(float)
        if v.ndim == 1 and v.size == n:
            channels[key] = v
        elif v.ndim == 2 and n in v.shape:
            cols = v if v.shape[0] == n else v.T
            names = (
                sensor_names
                if key == "response" and sensor_names and len(sensor_names) == cols.shape[1]
                else [f"{key}_{i + 1}" for i in range(cols.shape[1])]
            )
            channels.update({name: cols[:, i].copy() for i, name in enumerate(names)})
    # vectors of another length are not channels of this record (a frequency axis, a
    # calibration table) unless the user names one: then their length is the error to report
    others = {key: v.size for key, v in numeric.items() if v.ndim == 1 and v.size > 1 and key not in channels}
    return channels, file_fs, {"other_lengths": others}


def _struct_fields(arrays: dict) -> dict:
    """A MATLAB struct's fields as variables of their own (``data.head`` -> ``head``, or
    ``data.head`` when a variable of that name exists): labs often save a record as one
    struct, which read as 'no numeric channels'. One struct level; struct arrays are skipped."""
    out = {k: v for k, v in arrays.items() if v.dtype.names is None}
    for name, record in arrays.items():
        if record.dtype.names is None or record.size != 1:
            continue
        for field in record.dtype.names:
            value = record.flat[0][field]
            if isinstance(value, np.ndarray):
                out[field if field not in arrays and field not in out else f"{name}.{field}"] = value
    return out
