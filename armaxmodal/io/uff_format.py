"""Universal File Format type 58 (pyuff): one function per record, complete records only."""

from __future__ import annotations

import os
import struct
from pathlib import Path

import numpy as np

from armaxmodal.exceptions import DataError


# -- UFF ------------------------------------------------------------------------------
def read_uff_file(path: Path):
    sets = read_sets(path)
    series = [s for s in sets if s.get("type") == 58]
    if not series:
        raise DataError(f"{path.name}: no type-58 (function at node) data sets in this UFF file.")
    channels: dict[str, np.ndarray] = {}
    steps = set()
    for s in series:
        if int(s.get("func_type", 1)) != 1:
            raise DataError(
                f"{path.name}: data set '{s.get('id1', '')}' has function type "
                f"{s.get('func_type')}, not a time response (1); armaxmodal needs time histories."
            )
        name = str(s.get("id1", "")).strip() or f"node{s.get('rsp_node')}:{s.get('rsp_dir')}"
        if name in channels:
            raise DataError(f"{path.name}: two data sets are named '{name}'; give each channel its own id1.")
        data = np.asarray(s["data"])
        if np.iscomplexobj(data):
            raise DataError(f"{path.name}: data set '{name}' is complex; expected a real time history.")
        channels[name] = data.astype(float)
        steps.add(float(s.get("abscissa_inc", 0.0)))
    steps.discard(0.0)
    if len(steps) > 1:
        raise DataError(f"{path.name}: channels have different sample steps {sorted(steps)}.")
    file_fs = 1.0 / steps.pop() if steps else None
    return channels, file_fs, {}


def read_sets(path: Path) -> list[dict]:
    """Every data set of a UFF file (pyuff), a damaged or truncated file refused with the reason."""
    import pyuff

    try:
        sets = pyuff.UFF(str(path)).read_sets()
    except (
        ValueError,
        IndexError,
        KeyError,
        TypeError,
        UnicodeDecodeError,
        struct.error,
        OSError,
        EOFError,
        AttributeError,
    ) as exc:
        raise DataError(f"{path.name}: not a readable UFF file ({exc}).") from exc
    except Exception as exc:  # pyuff raises a bare Exception for a data set it cannot parse
        raise DataError(
            f"{path.name}: not a readable UFF file: a data set could not be parsed ({exc}). Check that it is a "
            "complete UFF export (each data set closed by a '-1' line), or export to CSV."
        ) from exc
    _check_uff_complete(path)
    return [sets] if isinstance(sets, dict) else list(sets)


def _check_uff_complete(path: Path) -> None:
    """Every UFF data set closes with a ``-1`` line; pyuff silently drops a set the file ends
    inside, so a truncated file would lose its last channels without a word."""
    with open(path, "rb") as fh:
        fh.seek(0, os.SEEK_END)
        fh.seek(max(fh.tell() - 256, 0))
        tail = fh.read().rstrip()
    if tail.rsplit(b"\n", 1)[-1].strip() != b"-1":
        raise DataError(
            f"{path.name}: the UFF file ends inside a data set (no closing '-1' line): it is truncated, "
            "and its last channels would be lost. Copy or export it again."
        )
