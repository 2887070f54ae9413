"""
The loop from the command line: a cubic spring planted, named and fixed
=======================================================================

Everything here is what a user types in a shell (each command is run as a subprocess, the way
a terminal runs it): ``simulate`` plants a cubic spring between chest and pelvis of the supine
body, ``diagnose`` is not told, names the effect and its joint, adds it, refits, and draws its
figure page.
"""

import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib.image as mpimg
import matplotlib.pyplot as plt

folder = Path(tempfile.mkdtemp())
armaxmodal = [sys.executable, "-m", "armaxmodal", "--quiet"]
commands = [
    ["simulate", "--effect", "stiffness_nonlinearity:chest+pelvis:ratio=0.3", "--out", "cubic.csv"],
    ["diagnose", "cubic.csv", "--plot", "cubic.png"],
]
for command in commands:
    print("$ armaxmodal " + " ".join(command))
    run = subprocess.run(armaxmodal + command, cwd=folder, capture_output=True, text=True, check=True)
    print(run.stdout)

# %%
# The figure page ``diagnose --plot`` wrote:
fig, ax = plt.subplots(figsize=(9, 7))
ax.imshow(mpimg.imread(folder / "cubic.png"))
ax.set_axis_off()
