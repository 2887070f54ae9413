"""Can two segments be lumped into one mass? Transmissibility relative to the base (Eq. 5.1),
Morlet scalograms and wavelet coherence (Eqs. 5.2-5.5), and a plain-language verdict
(thesis Chapter 5).

* :func:`lump_check` -- the verdict and its evidence.
* :func:`relative_transmissibility` -- Eq. 5.1 with its coherence.
* :func:`scalogram`, :func:`wavelet_coherence` -- Morlet (omega_0 = 5) CWT and squared
  wavelet coherence with phase lag and red-noise significance, on pycwt.
"""

from .check import LIMITS, LumpCheck, lump_check, relative_transmissibility
from .wavelet import Scalogram, WaveletCoherence, scalogram, wavelet_coherence

__all__ = [
    "LIMITS",
    "LumpCheck",
    "Scalogram",
    "WaveletCoherence",
    "lump_check",
    "relative_transmissibility",
    "scalogram",
    "wavelet_coherence",
]
