"""
An uncertain verdict: a hum on one sensor
=========================================

The bundled supine ride with a 0.3 m/s² hum at 12.5 Hz added to the legs' sensor, as mains or a
pump would put it there. The four modes are still found, but the record holds a line the input
does not drive, so the verdict is ``uncertain``: the notes say what was seen and what to do, per
code as the command line prints them (``--verbose`` and the JSON give every full text).
"""

from pathlib import Path

import numpy as np

import armaxmodal as am
from armaxmodal.quality_warnings import severity

folders = (Path.cwd(), *Path.cwd().parents)
fixtures = next(d / "fixtures" for d in folders if (d / "fixtures" / "supine_random.csv").exists())
clean = am.read_recording(fixtures / "supine_random.csv")
t = np.arange(clean.n_samples) / clean.fs
response = clean.response.copy()
response[:, clean.sensors.index("legs")] += 0.3 * np.sin(2 * np.pi * 12.5 * t)
hummed = am.Recording(clean.fs, clean.base, response, clean.sensors, clean.input_name)

diagram = am.stabilisation_diagram(hummed, orders=range(2, 21, 2), per_sensor=False)
selection = am.select_modes(diagram, segments=0)
print(selection.modes[["freq_hz", "damping", "freq_ci95_lo", "freq_ci95_hi"]].round(3).to_string())
print("quality:", selection.quality)
for note in selection.warnings:
    print(f"{severity(note.code):8s} {note.code}: {note.message[:90]}...")

# %%
# The diagram: the hum is the column of undamped poles at 12.5 Hz, apart from the modes.
ax, _ = diagram.plot(selection)
