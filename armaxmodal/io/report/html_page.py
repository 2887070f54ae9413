"""Self-contained HTML pages: one look for the study report and the one-record reports, figures
embedded as data URIs. No network: no script, font or style is fetched."""

from __future__ import annotations

import base64
import html
import io
import re

import pandas as pd

__all__ = ["STYLE", "SCRIPT", "figure_uri", "marked_up", "page", "table"]

STYLE = """
body{font-family:system-ui,sans-serif;margin:2em auto;max-width:1200px;padding:0 1em;color:#222}
h1{overflow-wrap:anywhere}nav{margin:1em 0}details{margin:.3em 0}details p{margin:.3em 1.2em}
table{border-collapse:collapse;margin:0.5em 0 1.5em;font-size:0.9em}
th,td{border:1px solid #ccc;padding:3px 8px;text-align:right}th{background:#f0f0f0}
td.gap{color:#b00;text-align:center}.thumbs{display:flex;flex-wrap:wrap;gap:10px}
figure{margin:0;text-align:center;font-size:0.8em}.thumbs img{width:260px;cursor:zoom-in;border:1px solid #ddd}
#full{display:none;position:fixed;inset:0;background:rgba(0,0,0,.8);align-items:center;justify-content:center}
#full.on{display:flex}#full img{max-width:95vw;max-height:95vh;background:#fff}
.fail{color:#900}.note{color:#555}img{max-width:100%}.wide{overflow-x:auto}
.verdict{font-size:1.15em;padding:.5em .8em;border-left:6px solid #888;background:#f7f7f7}
.text td{overflow-wrap:anywhere}.text td:first-child{overflow-wrap:normal;white-space:nowrap}
code{background:#f3f3f3;padding:0 .2em}
dl.glossary dt{font-weight:bold;margin-top:.5em}dl.glossary dd{margin-left:1.2em}
.verdict.good{border-color:#2a7}.verdict.uncertain{border-color:#d90}.verdict.poor{border-color:#c22}
"""
SCRIPT = """
document.querySelectorAll('.thumbs img').forEach(function(img){img.addEventListener('click',function(){
var f=document.getElementById('full');f.querySelector('img').src=img.src;f.classList.add('on');});});
var full=document.getElementById('full');
if(full){full.addEventListener('click',function(){this.classList.remove('on');});}
window.addEventListener('load',function(){var imgs=[].slice.call(document.querySelectorAll('img[src]'));
var ok=imgs.filter(function(i){return i.complete&&i.naturalWidth>0;}).length;
document.documentElement.dataset.figures=ok+'/'+imgs.length;
document.documentElement.dataset.overflow=document.documentElement.scrollWidth>window.innerWidth?'yes':'no';});
"""


def figure_uri(fig, dpi: int = 90) -> str:
    """A matplotlib figure as a ``data:image/png;base64,...`` URI."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def marked_up(text: str) -> str:
    """A note's text as HTML: escaped, its `code` spans set as code, not shown as backticks.

    Parameters
    ----------
    text : str

    Returns
    -------
    str

    Examples
    --------
    >>> from armaxmodal.io.report.html_page import marked_up
    >>> marked_up("widen `--orders` & retry")
    'widen <code>--orders</code> &amp; retry'
    """
    return re.sub(r"`([^`]+)`", r"<code>\1</code>", html.escape(text))


def table(frame: pd.DataFrame, digits: int = 4, text: bool = False) -> str:
    """A DataFrame as an HTML table (missing values shown as X), scrolling when wide; ``text``: a
    table of words (a command, a checksum, a path), whose long cells wrap on a narrow screen."""
    html_table = frame.to_html(index=False, na_rep="X", float_format=lambda v: f"{v:.{digits}g}", border=0)
    return f"<div class='wide{' text' if text else ''}'>{html_table}</div>"


def page(title: str, body: str) -> str:
    """The whole document around ``body`` (HTML), with the shared style and script."""
    return (
        f"<!DOCTYPE html><html lang=en><head><meta charset=utf-8><title>{html.escape(title)}</title>"
        f"<style>{STYLE}</style></head><body>{body}<script>{SCRIPT}</script></body></html>\n"
    )
