"""armaxmodal: time-domain modal analysis of base-excited structures and people.

Fits ARMAX models by the prediction-error method (PEM) to a base-acceleration input and
body/structure sensor outputs, turns poles and residues into modes, and solves the
inverse modal problem for a physical chain model. See ``shared/METHOD.md`` for the map
from the source thesis to the code.
"""

from .datasets import chapter2_system, supine_human, supine_with_feet
from .exceptions import (
    ArmaxModalError,
    ConvergenceWarning,
    DataError,
    OrderError,
    StructureError,
)
from .fit import ArmaxFit, fit_armax
from .identify import Identification, identify
from .io import read_recording, write_recording_csv, write_recording_uff
from .orders import choose_orders
from .recording import Recording
from .simulate import add_noise, random_vibration, simulate, simulate_recording, sine_sweep
from .structure import ChainComponents, ExactModes, Structure

__version__ = "0.1.0"

__all__ = [
    "ArmaxFit",
    "ArmaxModalError",
    "Identification",
    "choose_orders",
    "fit_armax",
    "identify",
    "ChainComponents",
    "ConvergenceWarning",
    "DataError",
    "ExactModes",
    "OrderError",
    "Recording",
    "Structure",
    "StructureError",
    "add_noise",
    "chapter2_system",
    "random_vibration",
    "read_recording",
    "simulate",
    "simulate_recording",
    "sine_sweep",
    "supine_human",
    "supine_with_feet",
    "write_recording_csv",
    "write_recording_uff",
]
