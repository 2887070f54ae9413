"""Figures of the lumping check: transmissibility (Fig. 5.5i-j), scalograms (Fig. 5.7) and
the squared wavelet coherence with phase arrows (Fig. 5.8)."""

from __future__ import annotations

import numpy as np

from armaxmodal.lumping.check import LIMITS, LumpCheck

__all__ = ["plot_lump"]

ARROW_R2 = 0.7  # arrows where the coherence exceeds this, as in Fig. 5.8


def plot_lump(check: LumpCheck):
    """One figure page: |T| and phase of ``b`` over ``a`` with the agreement band, the
    scalograms of the base and of both relative motions, and their wavelet coherence.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 3, figsize=(15, 8), layout="constrained")
    _transmissibility(axes[0, 0], axes[0, 1], check)
    if check.scalograms is not None:
        names = [k for k in check.scalograms if k != "base"]
        _scalogram(axes[0, 2], check.scalograms["base"], "base acceleration")
        _scalogram(axes[1, 0], check.scalograms[names[0]], f"{names[0]} relative to base")
        _scalogram(axes[1, 1], check.scalograms[names[1]], f"{names[1]} relative to base")
        _coherence(axes[1, 2], check)
    else:
        for ax in (axes[0, 2], axes[1, 0], axes[1, 1], axes[1, 2]):
            ax.set_axis_off()
    fig.suptitle(f"{check.a} and {check.b}: {check.verdict}", fontsize=12)
    return fig


def _transmissibility(ax_g, ax_p, check: LumpCheck) -> None:
    f, t = check.freq_hz, check.transmissibility
    used = check._used()
    for ax, values, label in ((ax_g, np.abs(t), "|T|"), (ax_p, np.degrees(np.angle(t)), "phase (deg)")):
        ax.plot(f, np.where(used, np.nan, values), color="0.7", lw=1, label="sensor noise dominates")
        ax.plot(f, np.where(used, values, np.nan), color="C0", lw=1.5, label="measurable")
        ax.axvspan(*check.band, color="C2", alpha=0.08, label="band")
        ax.set_xlabel("frequency (Hz)")
        ax.set_ylabel(label)
        ax.set_xlim(0, check.band[1] * 1.05)
    ax_g.axhspan(1 / LIMITS["gain"], LIMITS["gain"], color="C1", alpha=0.15, label="moves as one")
    ax_p.axhspan(-LIMITS["phase_deg"], LIMITS["phase_deg"], color="C1", alpha=0.15)
    ax_g.set_ylim(0, max(2.0, float(np.nanmax(np.abs(t[used]))) * 1.1) if used.any() else 2.0)
    ax_p.set_ylim(-180, 180)
    ax_g.set_title(f"transmissibility {check.b} / {check.a} (Eq. 5.1)")
    ax_g.legend(fontsize=7)


def _log_frequency_axis(ax, lo: float, hi: float) -> None:
    from matplotlib.ticker import NullFormatter, ScalarFormatter

    ax.set_yscale("log")
    ax.set_ylim(lo, hi)
    ax.yaxis.set_major_formatter(ScalarFormatter())
    ax.yaxis.set_minor_formatter(NullFormatter())
    ax.set_ylabel("frequency (Hz)")


def _scalogram(ax, sc, title: str) -> None:
    # power in dB below the strongest value: the colour bar reads the same on every panel
    db = 10 * np.log10(sc.power / sc.power.max() + 1e-30)
    mesh = ax.pcolormesh(sc.time_s, sc.freq_hz, db, shading="auto", cmap="viridis", vmin=-40, vmax=0)
    ax.figure.colorbar(mesh, ax=ax, label="power (dB below its peak)")
    ax.plot(sc.time_s, sc.coi_hz, "w--", lw=1)
    _log_frequency_axis(ax, sc.freq_hz.min(), sc.freq_hz.max())
    ax.set_title(f"Morlet scalogram, {title}", fontsize=9)
    ax.set_xlabel("time (s)")


def _coherence(ax, check: LumpCheck) -> None:
    w = check.wavelet
    mesh = ax.pcolormesh(w.time_s, w.freq_hz, w.r2, shading="auto", cmap="jet", vmin=0, vmax=1)
    ax.figure.colorbar(mesh, ax=ax, label="squared coherence")
    if np.isfinite(w.significance).any():
        ax.contour(w.time_s, w.freq_hz, w.r2 / w.significance[:, None], [1.0], colors="k", linewidths=0.8)
    ax.plot(w.time_s, w.coi_hz, "w--", lw=1)
    ti = np.linspace(0, w.time_s.size - 1, 40).astype(int)
    fi = np.arange(0, w.freq_hz.size, 4)
    tt, ff = np.meshgrid(w.time_s[ti], w.freq_hz[fi])
    r2 = w.r2[np.ix_(fi, ti)]
    ph = w.phase_rad[np.ix_(fi, ti)]
    show = r2 > ARROW_R2
    # an arrow pointing right: no lag; turned anticlockwise by the lag of b behind a
    ax.quiver(tt[show], ff[show], np.cos(ph[show]), np.sin(ph[show]), scale=28, width=0.004, color="k")
    _log_frequency_axis(ax, w.freq_hz.min(), w.freq_hz.max())
    ax.set_title(f"wavelet coherence {check.a}-{check.b} relative to base (Eqs. 5.4-5.5)", fontsize=9)
    ax.set_xlabel("time (s)")
