"""Systems with known truth: chain structures and their exact modes, the thesis's datasets,
and base-excitation simulation (what every test compares against).

* :class:`~armaxmodal.Structure` -- M, C, K of a base-excited chain; :class:`~armaxmodal.ExactModes` its modes.
* :func:`~armaxmodal.supine_human`, :func:`~armaxmodal.chapter2_system`,
  :func:`~armaxmodal.supine_with_feet` -- the thesis's systems.
* :func:`~armaxmodal.simulate_recording` -- a ride of a structure, band-limited or held.
"""

from armaxmodal.systems.datasets import chapter2_system, supine_human, supine_with_feet
from armaxmodal.systems.simulation import add_noise, random_vibration, simulate, simulate_recording, sine_sweep
from armaxmodal.systems.structure import ChainComponents, ExactModes, Structure

__all__ = [
    "ChainComponents",
    "ExactModes",
    "Structure",
    "add_noise",
    "chapter2_system",
    "random_vibration",
    "simulate",
    "simulate_recording",
    "sine_sweep",
    "supine_human",
    "supine_with_feet",
]
