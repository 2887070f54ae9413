"""One recording's result as one self-contained HTML page (``stabilise --report``), with the
study report's look: what a colleague needs to judge it without the files around it.

The page holds the verdict; the record (input, outputs, rates, preprocessing); every warning,
each saying what to do; the stabilisation diagram over the FRF; the modes with their intervals;
the modal-model check per output; the shapes; and the settings of the run.
"""

from __future__ import annotations

import html

import numpy as np
import pandas as pd

from armaxmodal.io.html_page import figure_uri, page, table

__all__ = ["render_selection_report", "modes_table"]


def modes_table(selection) -> pd.DataFrame:
    """The modes as a person reads them: frequency and damping with their 95 % intervals, the
    estimator, and whether the mode was picked by hand."""
    m = selection.modes
    freq_ci = zip(m.freq_ci95_lo, m.freq_ci95_hi, strict=True)
    damping_ci = zip(m.damping_ci95_lo, m.damping_ci95_hi, strict=True)
    out = pd.DataFrame({
        "mode": np.arange(1, len(m) + 1),
        "f (Hz)": m.freq_hz.to_numpy(float),
        "f 95 % interval (Hz)": [f"[{lo:.4g}, {hi:.4g}]" for lo, hi in freq_ci],
        "damping": m.damping.to_numpy(float),
        "damping 95 % interval": [f"[{lo:.3g}, {hi:.3g}]" for lo, hi in damping_ci],
    })  # fmt: skip
    if "estimator" in m:
        out["estimator"] = m.estimator.to_numpy()
    if "picked_hz" in m:
        out["picked at (Hz)"] = m.picked_hz.to_numpy(float)
    return out


def _check_table(check) -> pd.DataFrame:
    return pd.DataFrame({
        "output": list(check.sensors), "misfit (%)": 100 * check.error, "H1 random error (%)": 100 * check.random_error,
        "model error (%)": 100 * check.model_error, "delay (ms)": 1e3 * check.delay_s, "lines": check.n_lines,
    })  # fmt: skip


def _record_table(selection, source: str) -> pd.DataFrame:
    rec, prep = selection.diagram.recording, selection.diagram.preparation
    rows = [("file", source), ("input", rec.input_name), ("outputs", ", ".join(rec.sensors)),
            ("samples", f"{rec.n_samples}"), ("duration (s)", f"{rec.duration:.4g}")]  # fmt: skip
    if prep is not None:
        rows += [("sampling rate (Hz)", f"{prep.original_fs:g}"), ("analysed at (Hz)", f"{prep.analysis_fs:g}")]
    else:
        rows.append(("sampling rate (Hz)", f"{rec.fs:g}"))
    return pd.DataFrame(rows, columns=["", "value"])


def _settings_table(selection, settings: dict) -> pd.DataFrame:
    d, t = selection.diagram, selection.diagram.tolerances
    rows = [("orders na swept", f"{d.orders[0].na}-{d.orders[-1].na}"), ("input delay nk (samples)", d.orders[0].nk),
            ("stability tolerances", f"f {100 * t.freq:g} %, damping {100 * t.damping:g} %, shape 1-MAC {t.shape:g}"),
            ("inter-sample behaviour", None if selection.refinement is None else selection.refinement.hold),
            ("picks (Hz)", selection.picks)]  # fmt: skip
    rows += list(settings.items())
    return pd.DataFrame([(k, "" if v is None else str(v)) for k, v in rows], columns=["setting", "value"])


def render_selection_report(selection, verdict: str, source: str, settings: dict | None = None) -> str:
    """The HTML text of one recording's report.

    Parameters
    ----------
    selection : ModeSelection
    verdict : str
        The closing line the command line prints (``quality: ...``).
    source : str
        What was read (file names), for the title.
    settings : dict, optional
        More settings of the run to list (name -> value).

    Returns
    -------
    str
    """
    from armaxmodal.modes.shape_plot import plot_shapes

    esc = html.escape
    warnings = "".join(f"<li><b>{esc(w.code)}</b>: {esc(w.message)}</li>" for w in selection.warnings)
    ax, _ = selection.diagram.plot(selection)
    diagram = figure_uri(ax.figure, dpi=110)
    shapes = figure_uri(plot_shapes(selection), dpi=110) if len(selection.modes) else ""
    check = "" if selection.check is None else "<h2>The modal-model check per output</h2>" + table(
        _check_table(selection.check), 3
    )
    body = f"""
<h1>armaxmodal stabilise: {esc(source)}</h1>
<p class="verdict {esc(selection.quality)}">{esc(verdict)}</p>
<h2>The record</h2>{table(_record_table(selection, source))}
<h2>Warnings ({len(selection.warnings)})</h2>{"<ul>" + warnings + "</ul>" if warnings else "<p>none</p>"}
<h2>Stabilisation diagram over the measured FRF</h2><img alt='stabilisation diagram' src='{diagram}'>
<h2>Modes ({len(selection.modes)})</h2>{table(modes_table(selection), 5) if len(selection.modes) else "<p>none</p>"}
{check}
{"<h2>Mode shapes</h2><img alt='mode shapes' src='" + shapes + "'>" if shapes else ""}
<h2>Settings</h2>{table(_settings_table(selection, settings or {}))}
"""
    return page(f"armaxmodal stabilise: {source}", body)
