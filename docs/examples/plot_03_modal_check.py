"""
Are the modes right? The modal-model check, and what it can tell
================================================================

A set of modes is judged by how well it explains the measured FRF: its poles are kept, each
output's residues, a lower and an upper residual and a delay are fitted to the H1 by least
squares (LSFD), and the misfit beyond the H1's own random error is the *model error*; above
the limit (50 %) the set is *poor*.

How much a wrong set leaves depends on the damping. Here a three-storey shear frame on a
shake table is simulated at six damping levels; at each, the exact modes, the modes with the
second left out, and the modes with the second 3 % too high are checked. On a frame damped
below about 1 % both wrong sets fail clearly; at 2-3 % a missing mode sits just beyond the
limit and a 3 % error passes; on a heavily damped chain (the supine human, damping
0.26-0.35) the broad peaks absorb a missing mode and every set passes. The
:doc:`validation pages <../validation/real>` gives the check's record on real structures.
"""

import matplotlib.pyplot as plt
import numpy as np

import armaxmodal as am
from armaxmodal.modes import check_modes


def three_storey(damper: float) -> am.Structure:
    """Unit floor masses, 4 kN/m storeys, equal dampers (N s/m) between floors."""
    return am.Structure.from_chain(
        np.ones(3), np.array([4000.0, 0, 0]), np.array([damper, 0, 0]), np.full(2, 4000.0), np.full(2, damper)
    )


ride = am.random_vibration(fs=100.0, duration=120.0, band=(0.5, 40.0), seed=1)
rows = []
for damper in (0.6, 1.0, 1.5, 2.0, 3.0, 6.0):
    frame = three_storey(damper)
    exact = frame.modes()
    rec = am.simulate_recording(frame, ride, 100.0, noise=0.05, hold="bandlimited", seed=2)
    sets = (
        (exact.freq_hz, exact.damping),
        (np.delete(exact.freq_hz, 1), np.delete(exact.damping, 1)),
        (exact.freq_hz * [1, 1.03, 1], exact.damping),
    )
    errors = [100 * check_modes(rec, f, d).overall_error for f, d in sets]
    rows.append((100 * exact.damping[1], *errors))
    print(f"mode 2 damping {100 * exact.damping[1]:.2f} %: model error " + ", ".join(f"{e:.0f} %" for e in errors))

# %%
# The heavily damped supine chain, for comparison.
human = am.supine_human()
body = am.simulate_recording(
    human, am.random_vibration(fs=60.0, duration=120.0, band=(0.5, 28.0), seed=1), 60.0, noise=0.05, seed=2
)
modes = human.modes()
lean = check_modes(body, np.delete(modes.freq_hz, 1), np.delete(modes.damping, 1))
print(f"supine chain (mode 2 damping {100 * modes.damping[1]:.0f} %), mode 2 left out: ", end="")
print(f"model error {100 * lean.overall_error:.0f} %")

# %%
# Model error against the second mode's damping ratio.
rows = np.array(rows)
fig, ax = plt.subplots(figsize=(6.5, 3.8), layout="constrained")
for column, label in ((1, "exact modes"), (2, "mode 2 left out"), (3, "mode 2 3 % high")):
    ax.semilogx(rows[:, 0], rows[:, column], "o-", label=label)
supine = "supine chain, mode 2 left out"
ax.semilogx([100 * modes.damping[1]], [100 * lean.overall_error], "s", color="C1", label=supine)
ax.axhline(100 * lean.limit, color="k", ls="--", lw=1, label="limit")  # the check carries its limit
ax.set(xlabel="damping ratio of mode 2 (%)", ylabel="model error (%)")
_ = ax.legend(fontsize=8)  # a bare call prints its repr in the gallery
