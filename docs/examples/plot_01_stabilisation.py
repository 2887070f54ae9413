"""
Modes from a recording: the stabilisation diagram
=================================================

The bundled ride of the thesis's supine-human model (four sensors, 60 Hz, 120 s of random
base vibration) swept over the model order; the physical modes picked automatically and
compared with the exact modes of the model that made the ride.
"""

import json
from pathlib import Path

import armaxmodal as am

# the repository's bundled rides, found from wherever the example runs
folders = (Path.cwd(), *Path.cwd().parents)
fixtures = next(d / "fixtures" for d in folders if (d / "fixtures" / "supine_random.csv").exists())
rec = am.read_recording(fixtures / "supine_random.csv")
diagram = am.stabilisation_diagram(rec, orders=range(2, 21, 2), per_sensor=False)
selection = am.select_modes(diagram, segments=0)
print(selection.modes[["freq_hz", "damping", "freq_ci95_lo", "freq_ci95_hi"]].round(3))
print("quality:", selection.quality)

# %%
# The truth: Table 4.3 of the thesis, the exact modes of the simulated chain.
truth = json.loads((fixtures / "supine_random.truth.json").read_text())
print([round(m["freq_hz"], 2) for m in truth["modes"]])

# %%
# Every pole of the sweep over the measured FRF; the selected modes are marked.
ax, _ = diagram.plot(selection)
