"""Mode shapes drawn: each selected mode over the sensors in their order along the chain.

A shape is the column of EPFRF modal constants (Eq. 3.24) scaled to a unit largest component.
The top row draws its real part, the deflection a person reads, beside the magnitude; the bottom
row the phase of each component. A classically damped mode has every phase near 0 or ±180°; a
phase in between is a complex mode, or a component the record does not determine.
"""

from __future__ import annotations

import numpy as np

from armaxmodal.modal import normalised_shape

__all__ = ["plot_shapes"]


def plot_shapes(selection, fig=None, positions: dict | None = None):
    """One column per mode: the normalised shape's real part and magnitude, and its phase.

    Parameters
    ----------
    selection : ModeSelection
        Its ``modes`` (frequency, damping, ``picked_hz`` when picked by hand), ``shapes``
        ((n_sensors, n_modes) complex) and the recording's sensor names, in chain order.
    fig : matplotlib Figure, optional
        Drawn into (cleared first); a new one otherwise.
    positions : dict of str to float, optional
        Each sensor's place along the chain (a height in m, a storey number): the top row then
        draws the deflected chain, the real part across and the position up, beside the chain at
        rest. Every sensor needs one.

    Returns
    -------
    matplotlib Figure
    """
    import matplotlib.pyplot as plt

    modes, sensors = selection.modes, list(selection.diagram.recording.sensors)
    if positions is not None:
        check_positions(positions, sensors)
    n = max(len(modes), 1)
    if fig is None:
        fig = plt.figure(figsize=(max(1.2 + 2.3 * n, 5.5), 4.8), layout="constrained")
    fig.clear()
    axes = fig.subplots(2, n, sharex=positions is None, sharey="row", squeeze=False, height_ratios=(2, 1))
    x = np.arange(len(sensors))
    for k, m in enumerate(modes.itertuples(index=False)):
        phi = normalised_shape(selection.shapes[:, k])
        top, bottom = axes[0, k], axes[1, k]
        if positions is None:
            top.axhline(0.0, color="0.6", lw=0.8)
            top.plot(x, phi.real, "o-", color="tab:blue", label="real part")
            top.plot(x, np.abs(phi), "s", mfc="none", color="0.45", label="magnitude")
        else:
            _deflected_chain(top, phi, [positions[s] for s in sensors])
        picked = " (picked)" if np.isfinite(getattr(m, "picked_hz", np.nan)) else ""
        top.set_title(f"mode {k + 1}{picked}\n{m.freq_hz:.2f} Hz, ξ {m.damping:.3f}", fontsize=9)
        bottom.axhline(0.0, color="0.6", lw=0.8)
        bottom.plot(x, np.degrees(np.angle(phi)), "o", color="tab:orange")
        bottom.set_ylim(-200, 200)
        bottom.set_yticks([-180, -90, 0, 90, 180])
        bottom.set_xticks(x, sensors, rotation=45, ha="right", fontsize=8)
    if not len(modes):
        axes[0, 0].text(0.5, 0.5, "no mode selected", ha="center", va="center", transform=axes[0, 0].transAxes)
    axes[0, 0].set_ylabel("shape (largest = 1)" if positions is None else "position along the chain")
    axes[1, 0].set_ylabel("phase (deg)")
    if positions is None:
        axes[0, 0].set_ylim(-1.15, 1.15)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    if handles:
        fig.legend(handles, labels, loc="outside lower center", ncol=2, fontsize=8, frameon=False)
    fig.suptitle("Mode shapes (modal constants, Eq. 3.24; largest = 1)", fontsize=10)
    return fig


def check_positions(positions: dict, sensors) -> None:
    """Every sensor has a finite position and every position names a sensor; else a DataError."""
    from armaxmodal.exceptions import DataError

    missing = [s for s in sensors if s not in positions]
    unknown = [p for p in positions if p not in sensors]
    if missing or unknown:
        raise DataError(
            f"positions: every sensor needs one ({', '.join(sensors)}); missing {missing or 'none'}, "
            f"not a sensor {unknown or 'none'}."
        )
    bad = [k for k, v in positions.items() if not np.isfinite(float(v))]
    if bad:
        raise DataError(f"positions: {bad} are not finite numbers.")


def _deflected_chain(ax, phi: np.ndarray, where) -> None:
    """The chain at rest (dashed, at zero) and deflected by the shape's real part, in position order."""
    order = np.argsort(where)
    y = np.asarray(where, float)[order]
    ax.plot(np.zeros_like(y), y, "--", color="0.6", lw=0.8, label="at rest")
    ax.plot(phi.real[order], y, "o-", color="tab:blue", label="real part")
    ax.set_xlim(-1.15, 1.15)
