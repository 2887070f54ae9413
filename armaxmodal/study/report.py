"""The study as one self-contained HTML page: settings, tables, figures embedded as data
URIs, failures with reasons. No network: no script, font or style is fetched."""

from __future__ import annotations

import base64
import html
import io

import numpy as np
import pandas as pd

__all__ = ["render_report"]

STYLE = """
body{font-family:system-ui,sans-serif;margin:2em auto;max-width:1200px;color:#222}
table{border-collapse:collapse;margin:0.5em 0 1.5em;font-size:0.9em}
th,td{border:1px solid #ccc;padding:3px 8px;text-align:right}th{background:#f0f0f0}
td.gap{color:#b00;text-align:center}.thumbs{display:flex;flex-wrap:wrap;gap:10px}
figure{margin:0;text-align:center;font-size:0.8em}.thumbs img{width:260px;cursor:zoom-in;border:1px solid #ddd}
#full{display:none;position:fixed;inset:0;background:rgba(0,0,0,.8);align-items:center;justify-content:center}
#full.on{display:flex}#full img{max-width:95vw;max-height:95vh;background:#fff}
.fail{color:#900}.note{color:#555}img{max-width:100%}.wide{overflow-x:auto}
"""
SCRIPT = """
document.querySelectorAll('.thumbs img').forEach(function(img){img.addEventListener('click',function(){
var f=document.getElementById('full');f.querySelector('img').src=img.src;f.classList.add('on');});});
document.getElementById('full').addEventListener('click',function(){this.classList.remove('on');});
window.addEventListener('load',function(){var imgs=[].slice.call(document.querySelectorAll('img[src]'));
var ok=imgs.filter(function(i){return i.complete&&i.naturalWidth>0;}).length;
document.documentElement.dataset.figures=ok+'/'+imgs.length;});
"""


def _png(fig) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def _table(frame: pd.DataFrame, digits: int = 4) -> str:
    html_table = frame.to_html(index=False, na_rep="X", float_format=lambda v: f"{v:.{digits}g}", border=0)
    return f"<div class=wide>{html_table}</div>"


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
        parts.append(f"<h3>ride: {html.escape(str(ride))}</h3>" + _table(wide.reset_index()))
    return "".join(parts)


def _table_3_2(study) -> str:
    ps = study.tables.per_sensor.dropna(subset=["mode"])
    if ps.empty:
        return "<p>none</p>"
    wide = ps.pivot_table(
        index=["ride", "subject", "file", "sensor"], columns="mode", values="freq_hz", aggfunc="first", dropna=False
    )
    wide.columns = [f"f{m} (Hz)" for m in wide.columns]
    return _table(wide.reset_index(), 4)


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
            + _table(pd.DataFrame(rows), 5)
            + "<p>its modes</p>"
            + _table(pd.DataFrame(m["model_modes"]))
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
    from armaxmodal.notes import UNCERTAIN_CODES

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
        f"<h3>ride: {esc(str(ride))}</h3><img alt='mode shapes {esc(str(ride))}' src='{_png(fig)}'>"
        for ride, fig in shape_figures.items()
    )
    lump = (
        ""
        if lump_rows is None or lump_rows.empty
        else "<h2>Can the segments be lumped? (Chapter 5)</h2>" + _table(lump_rows)
    )
    body = f"""
<h1>armaxmodal study</h1>
<p>{len(study.recordings)} recordings analysed, {study.reused} of them reused from an earlier run;
{len(study.failures)} left out.</p>
<h2>Settings</h2>{_table(settings)}
{"<h2>Notes</h2><ul>" + notes + "</ul>" if notes else ""}
<h2>Across subjects (Table 3.3 form: mean and sample SD)</h2>{_table(study.tables.summary)}
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
    return (
        f"<!DOCTYPE html><html lang=en><head><meta charset=utf-8><title>armaxmodal study</title>"
        f"<style>{STYLE}</style></head><body>{body}<script>{SCRIPT}</script></body></html>\n"
    )
