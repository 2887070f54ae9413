"""One diagnosis as one self-contained HTML page (``diagnose --report``), with the study report's
look: the verdict, the record and its warnings, each output's fit before and after, each effect
found with its evidence, its fix and the held-out error before and after, the modes before and
after, and the figure page."""

from __future__ import annotations

import html

import pandas as pd

from armaxmodal.io.report.html_page import figure_uri, page, table

__all__ = ["effects_table", "render_diagnosis_report", "short_parameters"]


def short_parameters(params: dict) -> str:
    """A fix's parameters as a person reads them: numbers to 4 significant digits, nested ones too.

    Parameters
    ----------
    params : dict

    Returns
    -------
    str

    Examples
    --------
    >>> from armaxmodal.diagnosis.report import short_parameters
    >>> short_parameters({"na": 8, "added_modes": [{"freq_hz": 15.887815, "damping": 0.26535077}]})
    'na 8, added_modes [(freq_hz 15.89, damping 0.2654)]'
    """

    def fmt(v):
        if isinstance(v, float):
            return f"{v:.4g}"
        if isinstance(v, list):
            return "[" + ", ".join(fmt(x) for x in v) + "]"
        if isinstance(v, dict):  # an added mode, say: its numbers rounded like the rest
            return "(" + ", ".join(f"{k} {fmt(x)}" for k, x in v.items()) + ")"
        return str(v)

    return ", ".join(f"{k} {fmt(v)}" for k, v in params.items())


def effects_table(report: dict) -> pd.DataFrame:
    """One row per effect kept: its channels, the test's statistic and p, the held-out one-step
    error before and after the fix, and the fix's parameters (from ``Diagnosis.to_dict()``)."""
    rows = []
    for e in report["effects"]:
        params = {k: v for k, v in e["parameters"].items() if not isinstance(v, dict)}
        rows.append(
            {
                "effect": e["effect"],
                "channels": ", ".join(e["channels"]),
                "test": e["evidence"]["statistic"],
                "p": e["evidence"]["p"],
                "error before": e["error_before"],
                "error after": e["error_after"],
                "fix": short_parameters(params),
            }
        )
    return pd.DataFrame(rows, columns=["effect", "channels", "test", "p", "error before", "error after", "fix"])


def _fits_table(report: dict) -> pd.DataFrame:
    base, final = report["baseline"], report["final"]
    inputs = set(final["inputs_added"])

    def shown(values, after=True):  # null: an output made an input (after), or a diverging simulation
        return [
            ("now an input" if after and name in inputs else "diverges") if v is None else v
            for name, v in zip(report["outputs"], values, strict=True)
        ]

    return pd.DataFrame(
        {
            "output": report["outputs"],
            "fit before (%)": shown(base["fit_val_pct"], after=False),
            "fit after (%)": shown(final["fit_val_pct"]),
            "residual RMS after": shown(final["sim_resid_rms"]),
            "H1 noise floor": final["noise_floor_rms"],
        }
    )


def _modes_table(report: dict) -> pd.DataFrame:
    before, after = report["final"]["modes_before"], report["final"]["modes_after"]
    rows = [{"model": "before", **m} for m in before] + [{"model": "after", **m} for m in after]
    return pd.DataFrame(rows).rename(columns={"freq_hz": "f (Hz)", "freq_ci95_lo": "f low", "freq_ci95_hi": "f high"})


def render_diagnosis_report(result, source: str) -> str:
    """The HTML text of one diagnosis.

    Parameters
    ----------
    result : Diagnosis
    source : str
        What was read, for the title.

    Returns
    -------
    str
    """
    from armaxmodal.diagnosis.plot import plot_diagnosis

    esc = html.escape
    report = result.to_dict()
    warnings = "".join(f"<li><b>{esc(w['code'])}</b>: {esc(w['message'])}</li>" for w in report["warnings"])
    unconfirmed = "".join(
        f"<li>{esc(u['effect'])} on {esc(', '.join(u['channels']))}: {esc(u['reason'])}</li>"
        for u in report["unconfirmed"]
    )
    effects = effects_table(report)
    body = f"""
<h1>armaxmodal diagnose: {esc(source)}</h1>
<p class="verdict">verdict: {esc(report["verdict"])}</p>
<h2>The record</h2>{
        table(
            pd.DataFrame(
                [
                    ("file", source),
                    ("input", report["input"]),
                    ("outputs", ", ".join(report["outputs"])),
                    ("sampling rate (Hz)", f"{report['fs']:g}"),
                    ("analysed at (Hz)", f"{report['analysis_fs']:g}"),
                    ("baseline orders", str(report["orders"])),
                    ("validation", report["validation"]),
                ],
                columns=["", "value"],
            )
        )
    }
<h2>Warnings ({len(report["warnings"])})</h2>{"<ul>" + warnings + "</ul>" if warnings else "<p>none</p>"}
<h2>Each output's fit, before and after</h2>{table(_fits_table(report), 4)}
<h2>Effects found and fixed ({len(effects)})</h2>{table(effects, 4) if len(effects) else "<p>none kept</p>"}
{"<h2>Not confirmed</h2><ul>" + unconfirmed + "</ul>" if unconfirmed else ""}
<h2>Modes before and after</h2>{table(_modes_table(report), 5)}
<h2>Figures</h2><img alt='diagnosis figures' src='{figure_uri(plot_diagnosis(result), dpi=100)}'>
"""
    return page(f"armaxmodal diagnose: {source}", body)
