"""Can two segments be lumped into one mass? Transmissibility relative to the base (Eq. 5.1),
Morlet scalograms and wavelet coherence (Eqs. 5.2-5.5), and a plain-language verdict
(thesis Chapter 5).

* :func:`~armaxmodal.lumping.lump_check` -- the verdict and its evidence.
* :func:`relative_transmissibility` -- Eq. 5.1 with its coherence.
* :func:`scalogram`, :func:`wavelet_coherence` -- Morlet (omega_0 = 5) CWT and squared
  wavelet coherence with phase lag and red-noise significance, on pycwt.
"""

from __future__ import annotations

import importlib

# Loaded on first use (PEP 562): pycwt pulls in scipy.stats, 0.8 s that every CLI command
# paid when the parser registered ``lump``.
_HOME = {
    "LIMITS": "check",
    "LumpCheck": "check",
    "lump_check": "check",
    "relative_transmissibility": "check",
    "Scalogram": "wavelet",
    "WaveletCoherence": "wavelet",
    "scalogram": "wavelet",
    "wavelet_coherence": "wavelet",
}

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


def __getattr__(name: str):
    if name not in _HOME:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f".{_HOME[name]}", __name__), name)


def __dir__() -> list[str]:
    return sorted(__all__)
