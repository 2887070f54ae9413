"""
Can the feet be lumped with the legs? (thesis Chapter 5)
========================================================

Two rides of a supine subject with feet sensors: in one the feet are a mass of their own on
a spring (the thesis's five-segment chain), in the other they move with the legs. The check
compares the transmissibility of feet over legs relative to the base (Eq. 5.1) and their
wavelet coherence (Eqs. 5.2-5.5), and says in plain words whether one mass will do.
"""

import numpy as np

import armaxmodal as am
from armaxmodal.lumping.plot import plot_lump

chain = am.supine_with_feet()
ride = am.random_vibration(fs=60.0, duration=120.0, band=(0.5, 28.0), seed=5)
separate = am.simulate_recording(chain, ride, 60.0, noise=0.03, seed=6)
apart = am.lump_check(separate, "legs", "feet")
print(apart.verdict, "-", apart.message)

# %%
# The same subject with the feet moving as the legs do (the legs' motion, its own noise).
legs = separate.response[:, 3:4]
feet = am.add_noise(legs, 0.03, np.random.default_rng(7))
together = am.Recording(60.0, separate.base, np.column_stack([separate.response[:, :4], feet]), separate.sensors)
joined = am.lump_check(together, "legs", "feet")
print(joined.verdict, "-", joined.message)

# %%
# Transmissibility, scalograms and wavelet coherence of the separate feet.
fig = plot_lump(apart)
