"""One recording's result as one self-contained HTML page (``stabilise --report``), with the
study report's look: what a colleague needs to judge it without the files around it.

The page holds, under a list of its sections: the verdict; what made it (the package version, the
date, the command and the input's checksum); the record (input, outputs, rates); the notes, one
group per code with how it moves the verdict, what to do and every full text; the stabilisation
diagram over the FRF; the modes with their intervals; the modal-model check per output; the shapes;
the settings of the run that were used; and a glossary of its terms. MNE-Python's ``Report`` is the
model.
"""

from __future__ import annotations

import html

import numpy as np
import pandas as pd

from armaxmodal.io.report.glossary import glossary_html
from armaxmodal.io.report.html_page import figure_uri, marked_up, page, table

__all__ = ["render_selection_report", "modes_table"]


def modes_table(selection) -> pd.DataFrame:
    """The modes as a person reads them: frequency and damping with their 95 % intervals, each
    quantity at one precision (frequencies to 1 mHz, damping ratios to 1e-4), the estimator, and
    whether the mode was picked by hand."""
    m = selection.modes
    freq_ci = zip(m.freq_ci95_lo, m.freq_ci95_hi, strict=True)
    damping_ci = zip(m.damping_ci95_lo, m.damping_ci95_hi, strict=True)
    out = pd.DataFrame(
        {
            "mode": np.arange(1, len(m) + 1),
            "f (Hz)": [f"{f:.3f}" for f in m.freq_hz],
            "f 95 % interval (Hz)": [f"[{lo:.3f}, {hi:.3f}]" for lo, hi in freq_ci],
            "damping": [f"{x:.4f}" for x in m.damping],
            "damping 95 % interval": [f"[{lo:.4f}, {hi:.4f}]" for lo, hi in damping_ci],
        }
    )
    if "estimator" in m:
        out["estimator"] = m.estimator.to_numpy()
    if "picked_hz" in m and np.isfinite(m.picked_hz.to_numpy(float)).any():
        out["picked at (Hz)"] = m.picked_hz.to_numpy(float)
    return out


def _notes(warnings) -> str:
    """The notes grouped by code, in the order the stages raise them: per code how many, how it
    moves the verdict, what to do (:data:`armaxmodal.quality_warnings.CODES`) and every full text."""
    from armaxmodal.quality_warnings import CODES

    esc, known = html.escape, {c.code: c for c in CODES}
    order = {c.code: k for k, c in enumerate(CODES)}
    groups: dict[str, list] = {}
    for w in warnings:
        groups.setdefault(w.code, []).append(w)
    effects = ("makes the verdict uncertain", "warning", "informative")

    def effect(code: str) -> int:
        spec = known.get(code)
        return 0 if spec is not None and spec.uncertain else 2 if spec and spec.advice.startswith("Nothing") else 1

    items = []  # what moves the verdict first, then by the stage that raised it
    for code in sorted(groups, key=lambda c: (effect(c), order.get(c, len(order)))):
        spec, texts, level = known.get(code), groups[code], effect(code)
        advice = f"<p>{marked_up(spec.advice)}</p>" if spec is not None else ""
        full = "".join(f"<li>{marked_up(w.message)}</li>" for w in texts)
        items.append(
            f"<details{' open' if level < 2 else ''}><summary><b>{esc(code)}</b> ({len(texts)}): "
            f"{effects[level]}</summary>{advice}<ul>{full}</ul></details>"
        )
    return "".join(items) or "<p>none</p>"


def _made_by(provenance: dict) -> pd.DataFrame:
    """What made the page: the version, the date, the command and the input's checksum."""
    from datetime import UTC, datetime

    from armaxmodal._version import __version__

    rows = [
        ("armaxmodal", __version__),
        ("run at (UTC)", provenance.get("date") or datetime.now(UTC).strftime("%Y-%m-%d %H:%M:%S")),
        ("command", provenance.get("command")),
        ("input SHA-256", provenance.get("checksum")),
    ]
    return pd.DataFrame([(k, v) for k, v in rows if v], columns=["", "value"])


def _check_table(check) -> pd.DataFrame:
    """Per output the check's percentages to 0.1 %, its delay to 0.1 ms and its lines."""

    def tenths(values) -> list[str]:
        return [f"{v:.1f}" for v in values]

    return pd.DataFrame(
        {
            "output": list(check.sensors),
            "misfit (%)": tenths(100 * check.error),
            "H1 random error (%)": tenths(100 * check.random_error),
            "model error (%)": tenths(100 * check.model_error),
            "delay (ms)": tenths(1e3 * check.delay_s),
            "lines": check.n_lines,
        }
    )


def _record_table(selection, source: str) -> pd.DataFrame:
    rec, prep = selection.diagram.recording, selection.diagram.preparation
    rows = [
        ("file", source),
        ("input", rec.input_name),
        ("outputs", ", ".join(rec.sensors)),
        ("samples", f"{rec.n_samples}"),
        ("duration (s)", f"{rec.duration:.4g}"),
    ]
    if prep is not None:
        rows += [("sampling rate (Hz)", f"{prep.original_fs:g}"), ("analysed at (Hz)", f"{prep.analysis_fs:g}")]
    else:
        rows.append(("sampling rate (Hz)", f"{rec.fs:g}"))
    return pd.DataFrame(rows, columns=["", "value"])


def _settings_table(selection, settings: dict) -> pd.DataFrame:
    d, t = selection.diagram, selection.diagram.tolerances
    rows = [
        ("orders na swept", f"{d.orders[0].na}-{d.orders[-1].na}"),
        ("input delay nk (samples)", d.orders[0].nk),
        ("stability tolerances", f"f {100 * t.freq:g} %, damping {100 * t.damping:g} %, shape 1-MAC {t.shape:g}"),
        ("inter-sample behaviour", None if selection.refinement is None else selection.refinement.hold),
        ("picks (Hz)", selection.picks),
    ]
    rows += list(settings.items())  # a setting the run did not use is left out, not shown empty
    return pd.DataFrame([(k, str(v)) for k, v in rows if v is not None and v != ""], columns=["setting", "value"])


def render_selection_report(
    selection, verdict: str, source: str, settings: dict | None = None, provenance: dict | None = None
) -> str:
    """The HTML text of one recording's report.

    Parameters
    ----------
    selection : ModeSelection
    verdict : str
        The closing line the command line prints (``quality: ...``).
    source : str
        What was read (file names), for the title.
    settings : dict, optional
        More settings of the run to list (name -> value; None: not used, left out).
    provenance : dict, optional
        ``command`` (the full command line), ``checksum`` (the input's SHA-256) and ``date``
        (default: now, UTC); the package version is always given.

    Returns
    -------
    str
    """
    from armaxmodal.io.report.shape_plot import plot_shapes

    esc = html.escape
    import matplotlib.pyplot as plt

    ax, _ = selection.diagram.plot(selection)
    diagram = figure_uri(ax.figure, dpi=110)
    plt.close(ax.figure)  # the page holds the picture: a caller's session keeps no open figure
    shapes = ""
    if len(selection.modes):
        fig = plot_shapes(selection)
        shapes = figure_uri(fig, dpi=110)
        plt.close(fig)
    n_modes = len(selection.modes)
    sections = [
        ("record", "The record", table(_record_table(selection, source), text=True)),
        ("notes", f"Notes ({len(selection.warnings)})", _notes(selection.warnings)),
        ("diagram", "Stabilisation diagram over the measured FRF", f"<img alt='diagram' src='{diagram}'>"),
        ("modes", f"Modes ({n_modes})", table(modes_table(selection), 5) if n_modes else "<p>none</p>"),
        (
            "check",
            "The modal-model check per output",
            None if selection.check is None else table(_check_table(selection.check), 3),
        ),
        ("shapes", "Mode shapes", f"<img alt='mode shapes' src='{shapes}'>" if shapes else None),
        ("settings", "Settings", table(_settings_table(selection, settings or {}))),
        ("glossary", "Glossary", glossary_html()),
    ]
    sections = [(key, title, content) for key, title, content in sections if content is not None]
    nav = " · ".join(f"<a href='#{key}'>{esc(title)}</a>" for key, title, _ in sections)
    body = (
        f'<h1>armaxmodal stabilise: {esc(source)}</h1><p class="verdict {esc(selection.quality)}">{esc(verdict)}'
        f"</p>{table(_made_by(provenance or {}), text=True)}<nav>{nav}</nav>"
        + "".join(f"<h2 id={key}>{esc(title)}</h2>{content}" for key, title, content in sections)
    )
    return page(f"armaxmodal stabilise: {source}", body)
