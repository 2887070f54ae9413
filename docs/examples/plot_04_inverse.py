"""
From modes to masses, springs and dampers
=========================================

The inverse modal problem on the thesis's 4-DOF system (Table 2.1): a ride is simulated,
one ARMAX model identifies the modes, and the chain's components are recovered from them by
the convex inner problem and by model updating with standard errors, then compared with the
components that made the ride.
"""

import matplotlib.pyplot as plt
import numpy as np

import armaxmodal as am

system = am.chapter2_system()
truth = system.chain_components()
ride = am.random_vibration(fs=100.0, duration=120.0, band=(0.5, 45.0), seed=3)
rec = am.simulate_recording(system, ride, 100.0, noise=0.02, hold="zoh", seed=4)

found = am.identify(rec)
print(found.modes[["freq_hz", "damping", "freq_ci95_lo", "freq_ci95_hi"]].round(3))

# %%
# Eigenvalues and shapes of the identified modes; the first mass fixed at its true 6 kg.
lam = -found.modes.damping * 2 * np.pi * found.modes.freq_hz + 1j * 2 * np.pi * found.modes.damped_freq_hz
shapes = found.shapes
inner = am.inner_solve(lam.to_numpy(), shapes, m1=truth.masses[0])
updated = am.model_update(lam.to_numpy(), shapes, m1=truth.masses[0])
print(updated.to_frame().round(2).to_string())

# %%
# The components the table marks "no" are not identified: their 95 % interval reaches zero. They
# are the fourth mass's spring and damper to the base, a small part of what holds that mass (its
# spring to the third mass is about five times stiffer), so the modes hardly depend on them; the
# estimate may lie far from the truth in per cent, and the standard error says by how much.
table = updated.to_frame()
weak = (table.identified == "no").to_numpy()
for (_, row), true in zip(table[weak].iterrows(), truth.to_frame()["value"].to_numpy()[weak], strict=True):
    print(f"{row.component} at {row.location}: {row.value:.0f} ± {row['std']:.0f} {row.unit}, truth {true:.0f} "
          f"({(row.value - true) / row['std']:+.1f} standard errors)")

# %%
# Springs to the base and between masses: truth, inner solve, model updating.
labels = [f"k{i + 1}" for i in range(4)] + [f"ks{i + 1}" for i in range(3)]
values = {
    "truth": np.r_[truth.k, truth.k_s],
    "inner solve": np.r_[inner.components.k, inner.components.k_s],
    "model updating": np.r_[updated.components.k, updated.components.k_s],
}
errors = np.r_[updated.std.k, updated.std.k_s]
fig, ax = plt.subplots(figsize=(7, 3.5), layout="constrained")
x = np.arange(len(labels))
for i, (name, v) in enumerate(values.items()):
    ax.bar(x + (i - 1) * 0.27, v / 1000, 0.27, label=name, yerr=errors / 1000 if name == "model updating" else None)
ax.set(xticks=x, xticklabels=labels, ylabel="stiffness (kN/m)")
_ = ax.legend(fontsize=8)  # a bare call prints its repr in the gallery
