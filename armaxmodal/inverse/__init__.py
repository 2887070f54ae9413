"""Inverse modal problem: from modes to physical mass, stiffness and damping (thesis Ch. 2, 4).

* :func:`inner_solve` -- the well-posed convex inner problem of EVPHC (Eq. 2.14 residual,
  chain topology and signs, mass-ratio bounds of Eq. 2.18, scale fixed by a mass).
* :func:`inner_solve_sdp` -- the same for any coupling pattern, as a semi-definite program
  (Clarabel, conic form built directly), and the thesis's printed form for comparison.
* :func:`evphc` -- the thesis's outer optimisation over eigenvector phases.
* :func:`pia` -- the Pilkey-Inman iterative algorithm (PIA), the baseline: M given.
* :func:`model_update` -- weighted nonlinear least squares of the chain's physical values
  on frequencies, damping, mode shapes and transmissibility together.

Acronyms: EVPHC, eigenvector phase correction (the thesis's method); PIA, Pilkey-Inman
algorithm; EPFRF, equivalent point frequency response function.
"""

from armaxmodal.inverse.inner import inner_solve
from armaxmodal.inverse.phase_correction import evphc
from armaxmodal.inverse.pilkey_inman import pia
from armaxmodal.inverse.result import InverseSolution
from armaxmodal.inverse.sdp import inner_solve_sdp
from armaxmodal.inverse.update import model_update, weight_sweep
from armaxmodal.inverse.validate import predict_recording, scale_to_subject

__all__ = [
    "InverseSolution",
    "evphc",
    "inner_solve",
    "inner_solve_sdp",
    "model_update",
    "pia",
    "predict_recording",
    "scale_to_subject",
    "weight_sweep",
]
