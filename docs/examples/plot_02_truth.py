"""
A system with known truth: exact modes and a simulated ride
===========================================================

Every accuracy claim in armaxmodal is checked against a system whose modes are known
exactly. Here the thesis's supine-human chain (Table 4.3): its exact modes, a simulated
120 s random ride through an anti-alias filter, and the measured transmissibility (H1) of
each sensor against the exact one.
"""

import matplotlib.pyplot as plt
import numpy as np

import armaxmodal as am
from armaxmodal.spectra import measured_frf

human = am.supine_human()
print(human.modes().to_frame().round(4))

ride = am.random_vibration(fs=60.0, duration=120.0, band=(0.5, 28.0), seed=1)
rec = am.simulate_recording(human, ride, 60.0, noise=0.05, hold="bandlimited", seed=2)

# %%
# The measured H1 follows the exact transmissibility where the coherence is high.
f, h1, coherence = measured_frf(rec)
exact = human.transmissibility(f)
fig, ax = plt.subplots(figsize=(7, 4), layout="constrained")
for k, name in enumerate(rec.sensors):
    line = ax.semilogy(f, np.abs(h1[:, k]), lw=2.5, alpha=0.45, label=f"{name}, H1")[0]
    # the exact curve drawn over the measured one, thin and dark, so that both show
    ax.semilogy(f, np.abs(exact[:, k]), "--", color=line.get_color(), lw=1.2, zorder=3)
ax.set(xlabel="frequency (Hz)", ylabel="|T| (absolute over base acceleration)", xlim=(0, 28), ylim=(1e-2, 5))
_ = ax.legend(title="dashed: exact; wide, pale: measured", fontsize=8)  # a bare call prints its repr in the gallery
