"""armaxmodal: time-domain modal analysis of base-excited structures and people.

Fits ARMAX models by the prediction-error method (PEM) to a base-acceleration input and
body/structure sensor outputs, turns poles and residues into modes, and solves the inverse
modal problem for a physical chain model. The stages, in the order a recording goes through
them, are the subpackages :mod:`~armaxmodal.io`, :mod:`~armaxmodal.prepare`,
:mod:`~armaxmodal.estimate`, :mod:`~armaxmodal.modes`, then :mod:`~armaxmodal.diagnosis`,
:mod:`~armaxmodal.inverse` and :mod:`~armaxmodal.lumping`, and :mod:`~armaxmodal.study` over
many recordings; :mod:`~armaxmodal.systems` holds the systems with known truth.

The functions a user needs are here::

    import armaxmodal as am
    rec = am.read_recording("ride.csv")
    selection = am.select_modes(am.stabilisation_diagram(rec))
"""

from __future__ import annotations

import importlib

from armaxmodal._version import __version__
from armaxmodal.estimate import ArmaxFit, choose_orders, fit_armax
from armaxmodal.exceptions import (
    ArmaxModalError,
    ConvergenceWarning,
    DataError,
    OrderError,
    PickError,
    SettingsError,
    StructureError,
)
from armaxmodal.identification import Identification, identify
from armaxmodal.io import read_recording, read_xsens, write_recording_csv, write_recording_uff
from armaxmodal.modes import (
    ModeSelection,
    StabilisationDiagram,
    select_modes,
    stabilisation_diagram,
)
from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.recording import Recording
from armaxmodal.systems import (
    ChainComponents,
    ExactModes,
    Structure,
    add_noise,
    chapter2_system,
    random_vibration,
    simulate,
    simulate_recording,
    sine_sweep,
    supine_human,
    supine_with_feet,
)

# The later stages load on first use (PEP 562): the diagnosis, the study (dask) and the
# wavelet check (pycwt, scipy.stats) would add about a second to every command's start.
_LATER = {
    "diagnose": ("armaxmodal.diagnosis", "diagnose"),
    "Diagnosis": ("armaxmodal.diagnosis", "Diagnosis"),
    "run_study": ("armaxmodal.study", "run_study"),
    "write_study": ("armaxmodal.study", "write_study"),
    "track_modes": ("armaxmodal.study", "track_modes"),
    "write_track": ("armaxmodal.study", "write_track"),
    "lump_check": ("armaxmodal.lumping", "lump_check"),
    "model_update": ("armaxmodal.inverse", "model_update"),
    "evphc": ("armaxmodal.inverse", "evphc"),
    "pia": ("armaxmodal.inverse", "pia"),
    "inner_solve": ("armaxmodal.inverse", "inner_solve"),
    "inner_solve_sdp": ("armaxmodal.inverse", "inner_solve_sdp"),
    "InverseSolution": ("armaxmodal.inverse", "InverseSolution"),
}

__all__ = [
    "ArmaxFit",
    "ArmaxModalError",
    "ChainComponents",
    "ConvergenceWarning",
    "DataError",
    "ExactModes",
    "Identification",
    "ModeSelection",
    "OrderError",
    "QualityWarning",
    "Recording",
    "StabilisationDiagram",
    "Structure",
    "PickError",
    "SettingsError",
    "StructureError",
    "__version__",
    "add_noise",
    "chapter2_system",
    "choose_orders",
    "fit_armax",
    "identify",
    "random_vibration",
    "read_recording",
    "read_xsens",
    "select_modes",
    "simulate",
    "simulate_recording",
    "sine_sweep",
    "stabilisation_diagram",
    "supine_human",
    "supine_with_feet",
    "write_recording_csv",
    "write_recording_uff",
    *_LATER,
]


def __getattr__(name: str):
    if name not in _LATER:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    module, attribute = _LATER[name]
    return getattr(importlib.import_module(module), attribute)


def __dir__() -> list[str]:
    return sorted(__all__)
