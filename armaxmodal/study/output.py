"""A study's files, written whole or not at all."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

from armaxmodal.io.write import write_all
from armaxmodal.study.plot import plot_shapes
from armaxmodal.study.report import render_report
from armaxmodal.study.run import Study

__all__ = ["write_study", "lump_table"]


def lump_table(study: Study) -> pd.DataFrame:
    """One row per recording that has a lumping verdict."""
    rows = []
    for r in study.recordings:
        lump = r.get("lump")
        if lump:
            rows.append(
                {
                    "file": r["file"],
                    "subject": r["subject"],
                    "ride": r["ride"],
                    "verdict": lump["verdict"],
                    "first_disagreement_hz": lump["first_disagreement_hz"],
                    "message": lump["message"],
                }
            )
    return pd.DataFrame(rows, columns=["file", "subject", "ride", "verdict", "first_disagreement_hz", "message"])


def write_study(study: Study, out: str | Path, report: str | Path | None = None) -> list[Path]:
    """Write ``summary.csv``, ``modes.csv``, ``per_sensor.csv``, ``subjects.csv``,
    ``shapes.csv``, ``lump.csv`` (when asked), ``study.json``, ``shapes_<ride>.png`` and the
    HTML report (default ``out/report.html``) -- all staged, then moved in together.

    Parameters
    ----------
    study : Study
    out : str or Path
        The folder for the tables and figures (created).
    report : str or Path, optional
        Where the HTML report goes (default ``out/report.html``).

    Returns
    -------
    list of Path
        The files written.

    See Also
    --------
    armaxmodal.study.run_study : Run the study.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> import armaxmodal as am
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03,
    ...                                  seed=1)
    ...     _ = am.write_recording_csv(ride, pathlib.Path(folder) / "Sub01_ride.csv")
    ...     study = am.run_study(folder, pathlib.Path(folder) / "out", jobs=1)
    ...     written = am.write_study(study, pathlib.Path(folder) / "out")
    >>> sorted(p.name for p in written)[:3]
    ['modes.csv', 'per_sensor.csv', 'report.html']
    """
    import matplotlib.pyplot as plt

    out = Path(out)
    t = study.tables
    data = json.dumps(study.to_dict(), indent=1, allow_nan=False) + "\n"
    lumps = lump_table(study)
    figures = {ride: plot_shapes(t, ride, study.sensors) for ride in sorted(t.shapes.ride.unique())}
    try:
        html = render_report(study, figures, lumps)
        outputs = [
            (out / "summary.csv", lambda tmp: t.summary.to_csv(tmp, index=False)),
            (out / "modes.csv", lambda tmp: t.modes.to_csv(tmp, index=False)),
            (out / "per_sensor.csv", lambda tmp: t.per_sensor.to_csv(tmp, index=False)),
            (out / "subjects.csv", lambda tmp: t.subjects.to_csv(tmp, index=False)),
            (out / "shapes.csv", lambda tmp: t.shapes.to_csv(tmp, index=False)),
            (out / "study.json", lambda tmp: Path(tmp).write_text(data, encoding="utf-8")),
            (Path(report) if report else out / "report.html", lambda tmp: Path(tmp).write_text(html, "utf-8")),
        ]
        if study.scaled is not None:
            scaled = pd.DataFrame(study.scaled, columns=["ride", "subject", "mass_kg", "component", "value"])
            outputs.append((out / "model_scaled.csv", lambda tmp: scaled.to_csv(tmp, index=False)))
        if not lumps.empty:
            outputs.append((out / "lump.csv", lambda tmp: lumps.to_csv(tmp, index=False)))
        for ride, fig in figures.items():
            outputs.append(
                (out / f"shapes_{_safe(ride)}.png", lambda tmp, fig=fig: fig.savefig(tmp, dpi=110, format="png"))
            )
        return write_all(outputs)
    finally:
        for fig in figures.values():
            plt.close(fig)


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in str(name))
