"""Writing outputs: every file goes to a temporary name beside the target and is renamed over
it when complete, so a failed run leaves nothing behind; JSON is strict (no bare NaN). A target
that is not a regular file (``/dev/null``, a named pipe) is written into, not renamed over: run
as root, a rename puts a regular file in place of the device.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np

from armaxmodal.recording import Recording


# -- writers --------------------------------------------------------------------------
def atomic_write(path: str | os.PathLike, write: Callable[[str], None]) -> Path:
    """Call ``write(tmp_path)`` and move the file into place only if it succeeds."""
    return write_all([(path, write)])[0]


def write_all(outputs) -> list[Path]:
    """Write every ``(path, write)`` pair or none: each ``write(tmp)`` fills a temporary file
    beside its target; only when all have succeeded are they moved into place."""
    staged: list[tuple[str, Path]] = []
    try:
        for path, write in outputs:
            path = Path(path)
            staged.append((_staging_file(path), path))
            write(staged[-1][0])
        umask = os.umask(0)
        os.umask(umask)
        for tmp, path in staged:
            if _special(path):  # a device or a pipe takes the bytes; renamed over, it would be gone
                with open(tmp, "rb") as src, open(path, "wb") as dst:
                    shutil.copyfileobj(src, dst)
                continue
            os.chmod(tmp, 0o666 & ~umask)
            os.replace(tmp, path)
    finally:
        for tmp, _ in staged:
            if os.path.exists(tmp):
                os.unlink(tmp)
    return [path for _, path in staged]


def _special(path: Path) -> bool:
    """``path`` exists and is neither a regular file nor a folder (``/dev/null``, a named pipe)."""
    return path.exists() and not path.is_file() and not path.is_dir()


def _staging_file(path: Path) -> str:
    """A new temporary file beside ``path`` (its folder made if need be), or in the system's
    temporary folder for a special target (nothing is to be created in ``/dev``)."""
    if _special(path):
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp")
    else:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    return tmp


def write_recording_csv(recording: Recording, path: str | os.PathLike, float_format: str = "%.9g") -> Path:
    """Write ``time``, the input and every sensor as CSV, with subject lines if known.

    Parameters
    ----------
    recording : Recording
    path : str or path-like
        The CSV file to write (its folder must exist).
    float_format : str
        printf-style format of every value (the default keeps 9 significant digits).

    Returns
    -------
    Path
        The file written.

    See Also
    --------
    armaxmodal.write_recording_uff : Write a recording as UFF 58 records.
    armaxmodal.read_recording : Read it back.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> import armaxmodal as am
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 20.0, seed=1), 60.0, seed=2)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = am.write_recording_csv(ride, pathlib.Path(folder) / "ride.csv")
    ...     am.read_recording(path).sensors
    ('head', 'chest', 'pelvis', 'legs')
    """

    def write(tmp: str) -> None:
        with open(tmp, "w", encoding="utf-8", newline="") as fh:
            if recording.subject is not None:
                fh.write(f"# subject: {recording.subject}\n")
            if recording.mass_kg is not None:
                fh.write(f"# mass_kg: {recording.mass_kg:.6g}\n")
            frame = recording.to_frame()
            # Enough digits that the sampling rate read back from the times is exact.
            frame["time"] = [f"{t:.12g}" for t in frame["time"]]
            frame.to_csv(fh, index=False, float_format=float_format, lineterminator="\n")

    return atomic_write(path, write)


def write_recording_uff(recording: Recording, path: str | os.PathLike) -> Path:
    """Write every channel (input first) as a type-58 time-response data set.

    Parameters
    ----------
    recording : Recording
    path : str or path-like
        The UFF file to write (its folder must exist).

    Returns
    -------
    Path
        The file written.

    See Also
    --------
    armaxmodal.write_recording_csv : Write a recording as CSV.
    armaxmodal.read_recording : Read it back.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> import armaxmodal as am
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 20.0, seed=1), 60.0, seed=2)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     back = am.read_recording(am.write_recording_uff(ride, pathlib.Path(folder) / "ride.uff"))
    >>> back.sensors, round(back.fs, 3)  # UFF 58 stores the sampling interval in single precision
    (('head', 'chest', 'pelvis', 'legs'), 60.0)
    """
    import pyuff

    names = [recording.input_name, *recording.sensors]
    signals = [recording.base, *recording.response.T]

    def write(tmp: str) -> None:
        os.unlink(tmp)  # pyuff refuses to overwrite in 'add' mode; let it create the file
        uff = pyuff.UFF(tmp)
        for node, (name, x) in enumerate(zip(names, signals, strict=True), start=1):
            uff.write_sets(
                pyuff.prepare_58(
                    id1=name,
                    func_type=1,
                    rsp_node=node,
                    rsp_dir=3,
                    ref_node=1,
                    ref_dir=3,
                    ord_data_type=4,
                    abscissa_spacing=1,
                    abscissa_min=0.0,
                    abscissa_inc=1.0 / recording.fs,
                    num_pts=x.size,
                    data=np.asarray(x),
                    x=recording.time,
                    ordinate_spec_data_type=12,
                    abscissa_spec_data_type=17,
                    orddenom_spec_data_type=0,  # pyuff has no default for this one
                ),
                mode="add",
            )

    return atomic_write(path, write)


def finite_or_none(value) -> float | None:
    """``value`` as a plain float, or None where it is None, NaN or infinite (a strict-JSON number)."""
    return float(value) if value is not None and np.isfinite(value) else None


def strict_json(obj):
    """``obj`` with numpy values made plain and every non-finite float made ``None``: strict
    JSON has no NaN or Infinity, and strict parsers reject them."""
    if isinstance(obj, dict):
        return {str(k): strict_json(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [strict_json(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return strict_json(obj.tolist())
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not np.isfinite(obj):
        return None
    if isinstance(obj, complex):
        raise TypeError("cannot write a complex number to JSON; split it into real and imaginary parts")
    return obj


def write_json(obj, path: str | os.PathLike) -> Path:
    """Write ``obj`` as indented strict JSON (numpy values converted, NaN and infinities as
    ``null``; ``allow_nan=False`` so a bare NaN can never slip through).

    Parameters
    ----------
    obj : dict, list or scalar
        What to write; numpy arrays and scalars are converted.
    path : str or path-like
        The JSON file to write.

    Returns
    -------
    Path
        The file written.

    See Also
    --------
    armaxmodal.write_recording_csv : The recordings' writer beside it.

    Examples
    --------
    >>> import json, tempfile, pathlib
    >>> import numpy as np
    >>> from armaxmodal.io import write_json
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = write_json({"freq_hz": np.float64(5.83), "damping_sd": np.nan, "orders": np.arange(2, 5)},
    ...                       pathlib.Path(folder) / "modes.json")
    ...     json.loads(path.read_text())  # NaN is written as null: strict JSON any reader takes
    {'freq_hz': 5.83, 'damping_sd': None, 'orders': [2, 3, 4]}
    """
    clean = strict_json(obj)

    def write(tmp: str) -> None:
        with open(tmp, "w", encoding="utf-8") as fh:
            json.dump(clean, fh, indent=2, allow_nan=False)
            fh.write("\n")

    return atomic_write(path, write)
