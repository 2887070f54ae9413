"""
Modes picked by hand, the one-page report and a UFF file
=========================================================

Two modes of the bundled supine ride picked by frequency, as a user who knows where the body's
resonances lie would: each pick takes the diagram's nearest stable cluster and is reported from
the counted modal model, with its interval. The selection then goes out as the one-page HTML
report (what ``stabilise --report`` writes) and as a UFF 55 file that other modal tools read.
"""

import re
import tempfile
from pathlib import Path

import armaxmodal as am
from armaxmodal.io.report.selection_report import render_selection_report
from armaxmodal.io.report.shape_plot import plot_shapes
from armaxmodal.io.uff_modes import read_modes_uff, write_modes_uff

folders = (Path.cwd(), *Path.cwd().parents)
fixtures = next(d / "fixtures" for d in folders if (d / "fixtures" / "supine_random.csv").exists())
rec = am.read_recording(fixtures / "supine_random.csv")
diagram = am.stabilisation_diagram(rec, orders=range(2, 21, 2), per_sensor=False)
picked = am.select_modes(diagram, picks=[5.8, 13.7], segments=0)
print(picked.modes[["picked_hz", "freq_hz", "damping", "freq_ci95_lo", "freq_ci95_hi"]].round(3).to_string())
print("quality:", picked.quality)

# %%
# The report: one self-contained page (figures embedded), its sections in order.
out = Path(tempfile.mkdtemp())
page = render_selection_report(picked, f"quality: {picked.quality}", "supine_random.csv")
(out / "run.html").write_text(page)
print(f"run.html, {len(page) / 1e3:.0f} kB:", ", ".join(re.findall(r"<h2 id=\w+>(.*?)</h2>", page)))

# %%
# The UFF file, read back: the same frequencies and dampings, the shapes per sensor.
path = write_modes_uff(out / "modes.uff", picked.modes.freq_hz, picked.modes.damping, picked.shapes, rec.sensors)
back = read_modes_uff(path)
for mode in back["modes"]:
    print(f"{mode['freq_hz']:.3f} Hz, damping {mode['damping']:.3f}, sensors {', '.join(mode['shape'])}")

# %%
# The picked modes' shapes along the body, as the report shows them.
fig = plot_shapes(picked)
