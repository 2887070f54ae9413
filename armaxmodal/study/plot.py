"""A study's figures: every subject's mode shapes with their geometric mean (Fig. 3.7)."""

from __future__ import annotations

import numpy as np

from armaxmodal.study.tables import StudyTables

__all__ = ["plot_shapes"]


def plot_shapes(tables: StudyTables, ride: str, sensors):
    """Fig. 3.7 for one ride: per mode, each subject's shape magnitudes (largest component 1)
    as thin dashed lines and the geometric mean over subjects in black.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    shapes = tables.shapes[tables.shapes.ride == ride]
    geo = tables.geomean[tables.geomean.ride == ride]
    summary = tables.summary[tables.summary.ride == ride].set_index("mode")
    modes = sorted(int(m) for m in shapes["mode"].unique())
    ncols = min(max(len(modes), 1), 4)
    nrows = -(-max(len(modes), 1) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(3.2 * ncols, 3.4 * nrows), layout="constrained", squeeze=False)
    for ax in axes.flat[len(modes) :]:
        ax.set_axis_off()
    x = np.arange(1, len(sensors) + 1)
    for ax, mode in zip(axes.flat, modes, strict=False):
        for _, g in shapes[shapes["mode"] == mode].groupby("file"):
            mags = g.set_index("sensor").mag.reindex(sensors).to_numpy(float)
            ax.plot(x, mags, "--", lw=0.8, alpha=0.7)
        mean = geo[geo["mode"] == mode].set_index("sensor").geomean.reindex(sensors).to_numpy(float)
        ax.plot(x, mean, "k-", lw=2.2, label="geometric mean")
        f = summary.freq_hz_mean.get(mode, np.nan)
        ax.set_title(f"mode {mode}: {f:.2f} Hz")
        ax.set_xticks(x, sensors, rotation=30)
        ax.set_ylim(0, 1.05)
        ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel("|shape| (largest = 1)")
    axes[0, 0].legend(fontsize=7)
    fig.suptitle(f"mode shapes, ride '{ride}' (dashed: each recording)", fontsize=10)
    return fig
