"""Figures (the only module that imports matplotlib). Functions take ``ax=None`` and return axes."""

from __future__ import annotations

import textwrap

import numpy as np

from armaxmodal.spectra import excited_band, measured_frf
from armaxmodal.stats import H1_COHERENCE as COHERENT
from armaxmodal.stats import MAX_DAMPING

__all__ = ["plot_stabilisation", "plot_prediction"]

# class -> (marker, colour, label); distinct in shape and colour
_STYLE = {
    "new": ("o", "#9e9e9e", "new"),
    "f": ("^", "#1f77b4", "stable f"),
    "f+d": ("s", "#ff7f0e", "stable f, ξ"),
    "f+d+v": ("*", "#d62728", "stable f, ξ, shape"),
}
_LOW_COHERENCE = "#fff3b0"  # shading of the bands where some sensor's coherence is low
_PICKED = "tab:purple"  # the line of a mode picked by hand (an automatic mode's is black, dotted)
_UNDRIVEN = "tab:brown"  # a resonance named, not reported: the input does not drive it (``undriven_resonance``)
_MISFIT = "#e53935"  # shading of the bands the modal model does not explain


def plot_stabilisation(diagram, selection=None, ax=None):
    """Stabilisation diagram over the measured FRF, with a damping panel below.

    Frequency on x, model order on y, one marker per shared-pole pole by stability class
    (rejected poles faint), the selected modes as labelled vertical lines, the measured H1
    magnitude of every sensor and the FRF rebuilt from the selected modes on a log axis,
    low-coherence bands shaded. Returns ``(ax_top, ax_damping)``.
    """
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    if ax is None:
        fig, (ax, ax_d) = plt.subplots(
            2, 1, sharex=True, figsize=(8, 6.2), height_ratios=(3, 1.3), constrained_layout=True
        )
    else:
        fig = ax.figure
        ax_d = ax.inset_axes([0, -0.45, 1, 0.35], sharex=ax)
    poles = diagram.poles[diagram.poles.source == "shared"]
    rec = diagram.recording
    tol = diagram.tolerances
    rejected = poles[poles.rejected != ""]
    ax.scatter(
        rejected.freq_hz,
        rejected.na,
        marker="x",
        s=12,
        color="#bdbdbd",
        alpha=0.5,
        label=f"rejected ({len(rejected)})",
        zorder=2,
    )
    for cls, (marker, colour, label) in _STYLE.items():
        sel = poles[(poles.rejected == "") & (poles.cls == cls)]
        ax_d.scatter(sel.freq_hz, sel.damping, marker=marker, s=18, color=colour, alpha=0.8)
        ax.scatter(sel.freq_hz, sel.na, marker=marker, s=28, color=colour, label=f"{label} ({len(sel)})", zorder=3)
    ax.set_ylabel("model order na")
    ax.yaxis.set_major_locator(MaxNLocator(integer=True))  # orders are whole numbers
    ax.set_title(
        f"Stabilisation: tolerances f {100 * tol.freq:g} %, ξ {100 * tol.damping:g} %, "
        f"shape 1-MAC {tol.shape:g}; nk = {diagram.orders[0].nk}",
        fontsize=10,
        pad=28,
    )

    # the H1 and the coherence the check judged (its segments), when there is a check
    check = None if selection is None else selection.check
    f, h, coh = measured_frf(rec, None if check is None else check.nperseg)
    ax_f = ax.twinx()
    for k, s in enumerate(rec.sensors):
        ax_f.semilogy(f, np.abs(h[:, k]), lw=1.0, alpha=0.7, label=f"|H1| {s}")
    low = np.min(coh, axis=1) < COHERENT
    for lo, hi in _runs(f, low):
        ax.axvspan(lo, hi, color=_LOW_COHERENCE, alpha=0.5, zorder=0, lw=0)
    if selection is not None:
        _draw_check(ax, ax_f, f, selection)
        top = max(o.na for o in diagram.orders)
        labelled = False  # the legend names the picked modes' line once
        for m in selection.modes.itertuples(index=False):
            by_hand = np.isfinite(getattr(m, "picked_hz", np.nan))
            style = {"color": _PICKED, "lw": 1.2, "ls": "--"} if by_hand else {"color": "k", "lw": 0.8, "ls": ":"}
            ax.axvline(m.freq_hz, **style, label="mode picked by hand" if by_hand and not labelled else None)
            ax_d.axvline(m.freq_hz, **style)
            labelled |= by_hand
        undriven = [w.value for w in selection.warnings if w.code == "undriven_resonance"]
        for k, f_hz in enumerate(undriven):  # named where no mode is: its column's poles grow (rejected, faint)
            label = "resonance the input does not drive" if k == 0 else None
            ax.axvline(f_hz, color=_UNDRIVEN, lw=1.2, ls="-.", label=label)
        ax.set_ylim(0, top * 1.05)
    lo, hi = _frequency_span(diagram)
    ax.set_xlim(lo, hi)
    # the curves set the axis inside the input's band only: beyond it an H1 is noise over
    # noise (on the size benchmark's ride it rose to 300 above the 40 Hz band and squeezed
    # the structure's response into the bottom third)
    _limit_frf_axis(ax_f, f, h, lo, min(hi, excited_band(rec)[1]))
    if selection is not None:
        _label_modes(ax, selection.modes)
    ax_f.set_ylabel(f"|FRF| (output / {rec.input_name})")  # a force or a base acceleration, as the record names it
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax_f.get_legend_handles_labels()
    if low.any():  # say what the shading is
        from matplotlib.patches import Patch

        h2, l2 = h2 + [Patch(color=_LOW_COHERENCE, alpha=0.5)], l2 + [f"coherence < {COHERENT:g}"]
    fig.legend(h1 + h2, l1 + l2, fontsize=7, loc="outside lower center", ncol=4, frameon=False)
    ax_d.set_ylabel("damping ratio")
    ax_d.set_xlabel("frequency (Hz)")
    ax_d.set_ylim(0, MAX_DAMPING)
    return ax, ax_d


def _draw_check(ax, ax_f, f, selection) -> None:
    """The modal-model check's fitted FRF (dashed), the bands it fails to explain (red), and
    its verdict in the corner."""
    check = selection.check
    if check is None:
        return
    fitted, labelled = check.frf(f[f > 0]), False
    for k in range(fitted.shape[1]):
        # drawn over the lines the output was checked on only: beyond them the curve is the residual
        # terms extrapolated (a bridge's rose tenfold over its H1 below the lowest coherent line)
        lo, hi = check.checked_hz[k] if check.checked_hz else (-np.inf, np.inf)
        on = (f[f > 0] >= lo) & (f[f > 0] <= hi)
        if not on.any():
            continue
        label = None if labelled else "modal model (LSFD) on the checked lines"
        ax_f.semilogy(f[f > 0][on], np.abs(fitted[on, k]), lw=1.0, ls="--", color="k", alpha=0.6, label=label)
        labelled = True
    for i, (_, lo, hi) in enumerate(check.bands):
        label = "not explained by the modes" if i == 0 else None
        ax.axvspan(lo, hi, color=_MISFIT, alpha=0.25, zorder=0, lw=0, label=label)
    worst = np.nanmax(check.model_error) if np.isfinite(check.model_error).any() else np.nan
    verdict = "modes explain the FRF" if check.passed else "POOR: the modes do not explain the FRF"
    if check.unconfirmed_hz:
        where = ", ".join(f"{f:.2f}" for f in check.unconfirmed_hz)
        verdict = f"POOR: no coherent H1 confirms {where} Hz; elsewhere"
    said = f"{verdict}: model error up to {100 * worst:.0f} % beyond the H1's random error "
    said += f"(limit {100 * check.limit:.0f} %), coherence ≥ {COHERENT:g}"
    ax.text(
        0.01,
        0.01,
        textwrap.fill(said, 110),  # a line the axes hold: an unconfirmed mode's verdict ran past the figure's edge
        transform=ax.transAxes,
        fontsize=8,
        va="bottom",
        color="k" if check.passed else "#b00020",
    )


def _frequency_span(diagram) -> tuple[float, float]:
    """The band of the analysis: the user's band, else up to the input's excited band."""
    rec = diagram.recording
    f_hi = diagram.tolerances.max_freq_fraction * rec.fs
    band = None if diagram.preparation is None else diagram.preparation.band
    if band is not None:
        width = band[1] - band[0]
        return max(0.0, band[0] - 0.05 * width), min(f_hi, band[1] + 0.05 * width)
    return 0.0, min(f_hi, 1.1 * excited_band(rec)[1])


def _limit_frf_axis(ax_f, f, h, lo, hi, decades: float = 4.0) -> None:
    """Log FRF axis over the curves between ``lo`` and ``hi``, at most ``decades`` below the
    largest (a near-zero channel, e.g. a signal-generator reference, would stretch it)."""
    inside = (f >= lo) & (f <= hi) & (f > 0)
    mags = np.abs(h[inside])
    mags = mags[np.isfinite(mags) & (mags > 0)]
    if mags.size == 0:
        return
    top = float(mags.max()) * 2
    ax_f.set_ylim(max(float(mags.min()) / 2, top * 10**-decades), top)


def _label_modes(ax, modes) -> None:
    """Frequency and damping above each mode's line, lifted a row where it would overlap a
    label already placed (close modes get rows of their own)."""
    fig = ax.figure
    renderer = fig.canvas.get_renderer()
    placed, top_level = [], 0
    xmin, xmax = ax.get_xlim()
    for m in modes.itertuples(index=False):
        if not xmin <= m.freq_hz <= xmax:
            continue
        for level in range(len(modes)):
            label = ax.annotate(
                f"{m.freq_hz:.2f} Hz, ξ {m.damping:.3g}",
                (m.freq_hz, 1.0),
                xycoords=("data", "axes fraction"),
                xytext=(0, 3 + 11 * level),
                textcoords="offset points",
                ha="center",
                va="bottom",
                fontsize=8,
            )
            box = label.get_window_extent(renderer).expanded(1.05, 1.0)
            if not any(box.overlaps(other) for other in placed):
                placed.append(box)
                top_level = max(top_level, level)
                break
            label.remove()
    ax.set_title(ax.get_title(), fontsize=10, pad=6 + 11 * (top_level + 1))


def _runs(f, mask):
    """Contiguous frequency intervals where ``mask`` is true."""
    out, start = [], None
    for x, m in zip(f, mask, strict=True):
        if m and start is None:
            start = x
        if not m and start is not None:
            out.append((start, x))
            start = None
    if start is not None:
        out.append((start, f[-1]))
    return out


def plot_prediction(recording, prediction, fits=None, ax=None, window_s: float | None = 5.0):
    """Measured (solid) and predicted (dashed) acceleration per sensor (Figs. 4.8-4.9).

    ``prediction`` is (n_samples, n_sensors); ``fits`` the NRMSE fit per sensor for the
    titles; ``window_s`` shows the last seconds only (None: whole record). Returns the axes.
    """
    import matplotlib.pyplot as plt

    n = recording.n_sensors
    if ax is None:
        _, ax = plt.subplots(n, 1, sharex=True, figsize=(9, 1.9 * n + 0.6), layout="constrained")
    axes = np.atleast_1d(ax)
    t = recording.time
    sel = slice(None) if window_s is None else t >= t[-1] - window_s
    for k, a in enumerate(axes):
        a.plot(t[sel], recording.response[sel, k], lw=0.8, color="tab:blue", label="measured")
        a.plot(t[sel], prediction[sel, k], lw=0.8, ls="--", color="tab:red", label="predicted")
        title = recording.sensors[k] + ("" if fits is None else f"  (fit {fits[k]:.1f} %)")
        a.set_title(title, fontsize=9, loc="left")
        a.set_ylabel("m/s²")
    axes[0].legend(fontsize=8, loc="upper right")
    axes[-1].set_xlabel("time (s)")
    return axes
