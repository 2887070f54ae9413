"""Modes out to the field's exchange format and back: UFF 55 (data at nodes: one complex mode per
data set) with UFF 58 (the measured and synthesised FRFs), the files MATLAB toolboxes, commercial
modal suites, pyOMA2 and sdypy-EMA read. Written and read with pyuff.

Each sensor is a node (node ``k`` the ``k``-th sensor, its measured direction DOF 1); the node
names go into ID lines 2-5 as ``k=name`` (UFF 55 has no field for them). A mode is a
first-order complex eigenvalue data set (analysis type 3): the pole ``lambda`` in rad/s and the
shape, the EPFRF modal constants of Eq. 3.24.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

from armaxmodal.exceptions import DataError
from armaxmodal.io.uff_format import read_sets
from armaxmodal.io.write import atomic_write

__all__ = ["read_modes_uff", "write_modes_uff"]

#: UFF ID lines hold 80 characters; the node names fill lines 2-5
_ID_LINE = 80
_NODES_TAG = "armaxmodal nodes:"


def _node_lines(sensors) -> list[str]:
    """ID lines 2-5 naming node k as ``k=name``; refused when the names do not fit."""
    lines, line = [], _NODES_TAG
    for k, name in enumerate(sensors, start=1):
        if ";" in name or "=" in name:
            raise DataError(f"sensor name {name!r}: ';' and '=' cannot be written to a UFF node list; rename it.")
        token = f" {k}={name};"
        if len(line) + len(token) > _ID_LINE:
            lines.append(line)
            line = ""
        line += token
    lines.append(line)
    if len(lines) > 4:
        raise DataError(f"{len(sensors)} sensor names do not fit the UFF file's four ID lines; shorten them.")
    return lines + ["NONE"] * (4 - len(lines))


def write_modes_uff(path: str | os.PathLike, freq_hz, damping, shapes, sensors, frfs=()) -> Path:
    """Write modes as UFF 55 and FRFs as UFF 58, whole or not at all.

    Parameters
    ----------
    path : path-like
    freq_hz, damping : (n_modes,) array_like
        Undamped natural frequency (Hz) and damping ratio of each mode.
    shapes : (n_sensors, n_modes) complex array_like
        The modal constants (Eq. 3.24), one column per mode.
    sensors : sequence of str
        The sensor names, node 1, 2, ... in this order.
    frfs : sequence of (label, sensor index, freq_hz, values)
        FRFs of sensor over base acceleration (dimensionless): ``label`` names it (e.g.
        ``"measured H1"``), ``freq_hz`` evenly spaced.

    Returns
    -------
    Path
    """
    import pyuff

    from armaxmodal.modal import normalised_shape

    freq_hz, damping = np.asarray(freq_hz, float), np.asarray(damping, float)
    shapes = np.asarray(shapes, complex)
    wn = 2 * np.pi * freq_hz
    poles = -damping * wn + 1j * wn * np.sqrt(np.clip(1 - damping**2, 0.0, None))
    id2, id3, id4, id5 = _node_lines(list(sensors))
    zeros = np.zeros(len(sensors), complex)

    def write(tmp: str) -> None:
        os.unlink(tmp)  # pyuff refuses to overwrite in 'add' mode; let it create the file
        uff = pyuff.UFF(tmp)
        for m in range(freq_hz.size):
            uff.write_sets(
                pyuff.prepare_55(
                    model_type=1,
                    id1=f"armaxmodal mode {m + 1}: {freq_hz[m]:.6g} Hz, damping {damping[m]:.4g}, shape largest = 1",
                    id2=id2,
                    id3=id3,
                    id4=id4,
                    id5=id5,
                    analysis_type=3,
                    data_ch=2,
                    spec_data_type=12,
                    data_type=5,
                    n_data_per_node=3,
                    r1=normalised_shape(shapes[:, m]),
                    r2=zeros,
                    r3=zeros,
                    node_nums=list(range(1, len(sensors) + 1)),
                    load_case=1,
                    mode_n=m + 1,
                    eig=complex(poles[m]),
                    modal_a=0j,
                    modal_b=0j,
                ),
                mode="add",
            )
        for label, k, f, values in frfs:
            f = np.asarray(f, float)
            uff.write_sets(
                pyuff.prepare_58(
                    binary=0,
                    id1=f"{label}: {sensors[k]} / base",
                    id2="armaxmodal",
                    id3="NONE",
                    id4="NONE",
                    id5="NONE",
                    func_type=4,
                    rsp_node=k + 1,
                    rsp_dir=1,
                    ref_node=0,
                    ref_dir=1,
                    ord_data_type=6,
                    num_pts=f.size,
                    abscissa_spacing=1,
                    abscissa_min=float(f[0]),
                    abscissa_inc=float(f[1] - f[0]),
                    abscissa_spec_data_type=18,
                    ordinate_spec_data_type=12,
                    orddenom_spec_data_type=12,
                    abscissa_axis_units_lab="Hz",
                    ordinate_axis_units_lab="(m/s^2)/(m/s^2)",
                    data=np.asarray(values, complex),
                    x=f,
                ),
                mode="add",
            )

    return atomic_write(path, write)


def read_modes_uff(path: str | os.PathLike) -> dict:
    """The UFF 55 complex modes of a file, in the form of ``stabilise --json``'s ``outputs`` and
    ``modes`` (frequency, damping and the shape per sensor; no intervals: UFF has none).

    Parameters
    ----------
    path : path-like

    Returns
    -------
    dict
        ``{"outputs": [...], "modes": [{"freq_hz", "damping", "shape": {sensor: {"mag", "phase_deg"}}}]}``

    Raises
    ------
    DataError
        When the file holds no type-55 complex modes, or its data sets disagree on the nodes.
    """
    path = Path(path)
    sets = [s for s in read_sets(path) if s.get("type") == 55]
    if not sets:
        raise DataError(f"{path.name}: no type-55 (data at nodes) data sets; write modes with 'stabilise --uff'.")
    if any(int(s.get("analysis_type", 0)) != 3 for s in sets):
        raise DataError(
            f"{path.name}: the type-55 data sets are not complex modes (analysis type 3); armaxmodal "
            "reads complex modes, with their poles."
        )
    nodes = [tuple(np.asarray(s["node_nums"], int)) for s in sets]
    if len(set(nodes)) != 1:
        raise DataError(f"{path.name}: the modes are given at different nodes; one set of nodes is needed.")
    sensors = _node_names(sets[0], nodes[0])
    modes = []
    for s in sorted(sets, key=lambda s: int(s.get("mode_n", 0))):
        lam = complex(s["eig"])
        wn = abs(lam)
        shape = np.asarray(s["r1"], complex)
        modes.append(
            {
                "freq_hz": wn / (2 * np.pi),
                "damping": -lam.real / wn if wn > 0 else float("nan"),
                "shape": {
                    name: {"mag": float(abs(v)), "phase_deg": float(np.degrees(np.angle(v)))}
                    for name, v in zip(sensors, shape, strict=True)
                },
            }
        )
    return {"outputs": sensors, "modes": modes, "source": str(path)}


def _node_names(dataset: dict, nodes: tuple) -> list[str]:
    """The sensor names from ID lines 2-5 (``k=name``), or ``node k`` where a file has none."""
    text = " ".join(str(dataset.get(f"id{i}", "")) for i in (2, 3, 4, 5))
    named = dict(re.findall(r"(\d+)=([^;]+);", text.replace(_NODES_TAG, "")))
    return [named.get(str(k), f"node {k}").strip() for k in nodes]
