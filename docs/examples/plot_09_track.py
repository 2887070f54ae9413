"""
Many events of one structure: modes followed as the shaking grows
=================================================================

Seven rides of the supine body, each at a stronger input than the last, the body softened by a
known law (every frequency 4 % lower per tenfold input), and one ride planted 7 % below the law.
``track`` follows each mode across the events, fits its trend with the peak input and flags the
planted event, as ``armaxmodal track manifest.csv --out DIR`` does from the command line.
"""

import math
import tempfile
from pathlib import Path

import pandas as pd

import armaxmodal as am
from armaxmodal.study import StudySettings, plot_track, track_modes

body = am.supine_human()
folder = Path(tempfile.mkdtemp())
rows = []
for k, rms in enumerate((0.1, 0.2, 0.5, 0.7, 1.0, 2.0, 5.0)):
    law = (1 - 0.04 * math.log10(rms / 0.1)) * (0.93 if rms == 0.7 else 1.0)
    softened = am.Structure(body.M, body.C * law, body.K * law**2, body.names)
    ride = am.simulate_recording(
        softened, am.random_vibration(60.0, 60.0, rms=rms, seed=10 + k), 60.0, noise=0.03, seed=20 + k
    )
    am.write_recording_csv(ride, folder / f"event{k}.csv")
    rows.append({"file": f"event{k}.csv", "date": f"2026-{k + 1:02d}-15"})
pd.DataFrame(rows).to_csv(folder / "manifest.csv", index=False)

followed = track_modes(folder / "manifest.csv", folder / "out", StudySettings(orders=(2, 16)), jobs=1)

# %%
# Each mode's trend: the exact slopes are -0.04 times 5.83, 8.31, 13.50 and 16.25 Hz, that is
# -0.233, -0.332, -0.540 and -0.650 Hz per tenfold input.
print(followed.trends[["mode", "events", "median_hz", "slope_hz_per_decade", "slope_sd"]].round(3))

# %%
# The planted event, against the trend of the others:
print(followed.table[followed.table.flagged][["file", "mode", "freq_hz", "trend_hz", "z"]].round(2))

# %%
# Frequency and damping with their 95 % intervals against the peak input and the date; the
# flagged event ringed in red.
fig = plot_track(followed)
