"""The study as one self-contained HTML page (:mod:`armaxmodal.io.report.html_page`, the one-record
reports' look): settings, tables, figures embedded as data URIs, failures with reasons."""

from __future__ import annotations

import html

import numpy as np
import pandas as pd

from armaxmodal.io.report.html_page import figure_uri, page, table

__all__ = ["render_report"]


def _table_3_3(study) -> str:
    """Per ride: each subject's modes, then the Average and SD rows (Table 3.3 form)."""
    parts = []
    for ride, g in study.tables.subjects.groupby("ride"):
        wide = g.pivot(index="subject", columns="mode", values=["freq_hz", "damping"])
        wide.columns = [
            f"{'f' if v == 'freq_hz' else 'ξ'}{m}{' (Hz)' if v == 'freq_hz' else ''}" for v, m in wide.columns
        ]
        s = study.tables.summary[study.tables.summary.ride == ride].set_index("mode")
        avg = [s.freq_hz_mean.get(m, np.nan) for m in s.index] + [s.damping_mean.get(m, np.nan) for m in s.index]
        sd = [s.freq_hz_sd.get(m, np.nan) for m in s.index] + [s.damping_sd.get(m, np.nan) for m in s.index]
        if len(avg) == wide.shape[1]:
            wide.loc["Average"] = avg
            wide.loc["SD"] = sd
        parts.append(f"<h3>ride: {html.escape(str(ride))}</h3>" + table(wide.reset_index()))
    return "".join(parts)


def _table_3_2(study) -> str:
    ps = study.tables.per_sensor.dropna(subset=["mode"])
    if ps.empty:
        return "<p>none</p>"
    wide = ps.pivot_table(
        index=["ride", "subject", "file", "sensor"], columns="mode", values="freq_hz", aggfunc="first", dropna=False
    )
    wide.columns = [f"f{m} (Hz)" for m in wide.columns]
    return table(wide.reset_index(), 4)


def _models(study) -> str:
    if study.models is None:
        return ""
    parts = ["<h2>Physical model of the average subject (Section 4.4; Eq. 4.7 scales it to each subject)</h2>"]
    for m in study.models:
        ride = html.escape(str(m["ride"]))
        if "reason" in m:
            parts.append(f"<p class=fail>ride {ride}: no model ({html.escape(m['reason'])})</p>")
            continue
        comps = m["components"]
        rows = [
            {"component": f"{name}{i + 1}", "value": float(v)}
            for name in ("masses", "k", "c", "k_s", "c_s")
            for i, v in enumerate(comps[name])
        ]
        parts.append(
            f"<h3>ride: {ride} ({m['mass_kg']:.1f} kg)</h3>"
            + table(pd.DataFrame(rows), 5)
            + "<p>its modes</p>"
            + table(pd.DataFrame(m["model_modes"]))
        )
        parts += [f"<p class=note>{html.escape(f)}</p>" for f in m.get("flags", [])]
    return "".join(parts)


def render_report(study, shape_figures: dict, lump_rows: pd.DataFrame | None = None) -> str:
    """The HTML text of the report (see module docstring).

    Parameters
    ----------
    study : Study
    shape_figures : dict
        ride -> matplotlib Figure of the mode shapes.
    lump_rows : DataFrame, optional
        One row per recording with a lumping verdict.
    """
    esc = html.escape
    settings = pd.DataFrame([{"setting": k, "value": str(v)} for k, v in study.to_dict()["settings"].items()])
    fails = "".join(f"<li class=fail><b>{esc(f['file'])}</b>: {esc(str(f['reason']))}</li>" for f in study.failures)
    notes = "".join(f"<li class=note>{esc(n)}</li>" for n in study.notes)
    from armaxmodal.quality_warnings import UNCERTAIN_CODES

    flagged = {"poor": ("modes_do_not_explain_frf",), "uncertain": UNCERTAIN_CODES}
    poor = "".join(
        f"<li class=fail><b>{esc(r['file'])}</b> ({r['quality']}): "
        + esc("; ".join(w["message"] for w in r.get("warnings", []) if w["code"] in flagged[r["quality"]]))
        + "</li>"
        for r in study.recordings
        if r.get("quality") in flagged
    )
    poor = "<ul>" + poor + "</ul>" if poor else "<p>none</p>"
    thumbs = "".join(
        f"<figure><img alt='stabilisation diagram of {esc(r['file'])}' "
        f"src='data:image/png;base64,{r['figure_png']}'><figcaption>{esc(r['file'])}</figcaption></figure>"
        for r in study.recordings
        if r.get("figure_png")
    )
    shapes = "".join(
        f"<h3>ride: {esc(str(ride))}</h3><img alt='mode shapes {esc(str(ride))}' src='{figure_uri(fig)}'>"
        for ride, fig in shape_figures.items()
    )
    lump = (
        ""
        if lump_rows is None or lump_rows.empty
        else "<h2>Can the segments be lumped? (Chapter 5)</h2>" + table(lump_rows)
    )
    body = f"""
<h1>armaxmodal study</h1>
<p>{len(study.recordings)} recordings analysed, {study.reused} of them reused from an earlier run;
{len(study.failures)} left out.</p>
<h2>Settings</h2>{table(settings)}
{"<h2>Notes</h2><ul>" + notes + "</ul>" if notes else ""}
<h2>Across subjects (Table 3.3 form: mean and sample SD)</h2>{table(study.tables.summary)}
<h2>Per subject</h2>{_table_3_3(study)}
<h2>Mode shapes (Fig. 3.7 form)</h2>{shapes}
{_models(study)}
{lump}
<h2>Failures</h2>{"<ul>" + fails + "</ul>" if fails else "<p>none</p>"}
<h2>Recordings whose modes do not explain their FRF (quality: poor) or that do not settle them (uncertain)</h2>{poor}
<h2>Stabilisation diagrams (click to enlarge)</h2><div class=thumbs>{thumbs}</div>
<details><summary><b>Per sensor (Table 3.2 form; X: the sensor's own model does not show the mode)</b></summary>
{_table_3_2(study)}</details>
<div id=full><img alt='enlarged figure'></div>
"""
    return page("armaxmodal study", body)
