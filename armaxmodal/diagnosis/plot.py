"""The diagnosis figure page: residual correlations with their bounds, residual spectra with
the lines found, the model FRF against H1, and before/after traces of the affected sensor."""

from __future__ import annotations

import numpy as np
from scipy import stats

from armaxmodal.diagnosis.model import usable
from armaxmodal.spectra import excited_band, measured_frf
from armaxmodal.stats import welch_nperseg

__all__ = ["plot_diagnosis"]


def plot_diagnosis(diagnosis, max_lag: int = 25):
    """Draw ``diagnosis`` on a new 2 x 3 figure; returns the figure (no display needed)."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 3, figsize=(15, 8), constrained_layout=True)
    final = diagnosis.final.model
    s = final.signals
    mask = usable(s.n, final.spec)
    eps = final.one_step_errors()[mask]
    n = eps.shape[0]
    _autocorrelation(axes[0, 0], eps, s.sensors, max_lag, n)
    _cross_correlation(axes[0, 1], diagnosis.tests.get("cross_correlation"), s.sensors)
    _spectra(axes[0, 2], diagnosis, mask)
    _frf(axes[1, 0], diagnosis)
    _traces(axes[1, 1], diagnosis)
    _summary(axes[1, 2], diagnosis)
    return fig


def _autocorrelation(ax, eps, names, max_lag, n):
    lags = np.arange(1, max_lag + 1)
    for k, name in enumerate(names):
        e = eps[:, k] - eps[:, k].mean()
        r = np.array([e[j:] @ e[:-j] for j in lags]) / (e @ e)
        ax.plot(lags, r, marker=".", label=name)
    bound = stats.norm.ppf(0.995) / np.sqrt(n)
    ax.axhspan(-bound, bound, color="0.85", zorder=0, label="99 % white-noise band")
    ax.set(title="final model: residual autocorrelation", xlabel="lag (samples)", ylabel="correlation")
    ax.legend(fontsize=7)


def _cross_correlation(ax, cc, names):
    if not cc:
        ax.set_axis_off()
        return
    lags = np.asarray(cc["lags"])
    for k, name in enumerate(names):
        line = ax.plot(lags, cc["ccf"][k], marker=".", label=name)[0]
        ax.axhline(cc["bound99"][k], color=line.get_color(), ls=":", lw=0.8)
        ax.axhline(-cc["bound99"][k], color=line.get_color(), ls=":", lw=0.8)
    ax.set(title="residual-input cross-correlation (99 % bounds dotted)", xlabel="lag (samples; > 0: input first)")
    ax.legend(fontsize=7)


def _psd(x, fs):
    from scipy.signal import welch

    return welch(x, fs, nperseg=welch_nperseg(x.shape[0], fs, seconds=20.0, max_fraction=1), axis=0)


def _spectra(ax, diagnosis, mask):
    fs = diagnosis.final.model.signals.fs
    outputs = diagnosis.final.model.signals.sensors  # both over the outputs left (a second input leaves)
    for stage, style, label in ((diagnosis.baseline, "-", "before"), (diagnosis.final, "--", "after")):
        columns = [stage.model.signals.sensors.index(name) for name in outputs]
        f, p = _psd(stage.model.simulation_errors()[mask][:, columns], fs)
        ax.semilogy(f, p.mean(axis=1), style, label=f"simulation residual, {label} (mean over sensors)")
    for e in diagnosis.effects:
        if e.finding.effect == "periodic_disturbance":
            ax.axvline(e.parameters["freq_hz"], color="C3", lw=0.8)
            f0 = e.parameters["freq_hz"]
            ax.annotate(f"{f0:.3f} Hz", (f0, 0.95), xycoords=("data", "axes fraction"), fontsize=8, color="C3")
    ax.set(title="residual spectrum (lines found in red)", xlabel="frequency (Hz)", ylabel="PSD")
    ax.legend(fontsize=7)


def _frf(ax, diagnosis):
    s = diagnosis.final.model.signals
    from armaxmodal.recording import Recording

    rec = Recording(s.fs, s.u, s.y - diagnosis.final.model.disturbance(), s.sensors, s.input_name)
    f, h, _ = measured_frf(rec)
    lo, hi = excited_band(rec)  # outside it the H1 divides noise by noise (1e5 above a 28 Hz input band)
    band = (f >= lo) & (f <= hi)
    for k, (name, m) in enumerate(zip(s.sensors, diagnosis.final.model.fit.models, strict=True)):
        line = ax.semilogy(f[band], np.abs(h[band, k]), lw=0.8, label=f"{name} H1")[0]
        ax.semilogy(f[band], np.abs(m.frf(f[band])[:, 0]), "--", color=line.get_color(), lw=1.2)
    ax.set(title="final model FRF (dashed) against H1, the input's band", xlabel="frequency (Hz)", ylabel="|T|")
    ax.legend(fontsize=7)


def _traces(ax, diagnosis):
    s = diagnosis.final.model.signals

    def driven(e):  # a second input's channel is no output: the outputs it drives, hardest first
        share = e.parameters.get("rms_share_of_output", {})
        return sorted(share, key=lambda name: -share[name])

    named = [c for e in diagnosis.effects for c in (*e.finding.channels, *driven(e))]
    affected = [c for c in named if c in s.sensors]
    k = s.sensors.index(affected[0]) if affected else 0
    # inside the second half, predicted by the first half's model: its middle 10 s at most (a
    # fixed offset ran past the end of a 21 s record, and the figure raised instead of drawing)
    half = s.n - s.n // 2
    n_show = min(half, int(10 * s.fs))
    start = s.n // 2 + (half - n_show) // 2
    t = np.arange(start, start + n_show) / s.fs
    ax.plot(t, diagnosis.baseline.held.simulation[start : start + n_show, k], lw=0.8, label="simulation error before")
    ax.plot(t, diagnosis.final.held.simulation[start : start + n_show, k], lw=0.8, label="simulation error after")
    ax.set(title=f"held-out errors of '{s.sensors[k]}'", xlabel="time (s)")
    ax.legend(fontsize=7)


def _fits(stage) -> dict[str, str]:
    """Each output's held-out simulation fit (%), or "diverges" where the simulation does."""
    s = stage.model.signals
    if not stage.held.simulates:
        return dict.fromkeys(s.sensors, "diverges")
    return {name: f"{v:.1f}" for name, v in zip(s.sensors, stage.held.fit_percent(s.y), strict=True)}


def _summary(ax, diagnosis):
    ax.set_axis_off()
    # what was kept, not the verdict's reading of the residual: that is the report's and the text's
    lines = ["effects kept:"] if diagnosis.effects else ["no effect kept"]
    for e in diagnosis.effects:
        where, judged = ", ".join(e.finding.channels), e.judged_by()
        lines.append(f"  {e.finding.effect} {where}: {judged['error']} {judged['before']:.4g} -> {judged['after']:.4g}")
        if "outputs_lag_ms" in e.parameters:
            lo, hi = e.parameters["outputs_lag_ci95_ms"]
            lines.append(f"    every output lags by {e.parameters['outputs_lag_ms']:.3g} ms ({lo:.3g} to {hi:.3g})")
        elif "delay_ci95_ms" in e.parameters:
            lo, hi = e.parameters["delay_ci95_ms"]
            lines.append(f"    late by {e.parameters['delay_ms']:.3g} ms ({lo:.3g} to {hi:.3g})")
    for u in diagnosis.unconfirmed:
        lines.append(f"unconfirmed: {u['effect']} {', '.join(u['channels'])}")
    base, final = (_fits(stage) for stage in (diagnosis.baseline, diagnosis.final))
    # an output a second input took has no fit after
    pairs = [f"{base[name]} -> {final.get(name, 'input')}" for name in base]
    lines.append("held-out simulation fit %:\n  " + ", ".join(pairs))
    ax.text(0, 1, "\n".join(lines), va="top", family="monospace", fontsize=8, wrap=True)
