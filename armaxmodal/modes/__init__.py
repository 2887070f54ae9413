"""From fits to modes (thesis Sections 3.3-3.4).

* :func:`~armaxmodal.stabilisation_diagram` -- the order sweep and its pole table (:mod:`.diagram`,
  :mod:`.poles`).
* :func:`~armaxmodal.select_modes` -- the physical modes picked from it by named stages
  (:mod:`.pipeline` over :mod:`.state`, every threshold in :mod:`.settings`, the result in :mod:`.result`;
  :mod:`.clusters`, the FRF's support tests and screen in :mod:`.frf`), refitted in the
  frequency domain (:func:`.state.refine_modes`), counted by nested tests of the maximum-likelihood modal
  model (fitted by :mod:`armaxmodal.estimate.dft_model`; :mod:`.mode_count`, :mod:`.count_search`,
  :mod:`.counted`, notes in :mod:`.notes`), with intervals widened by the segment spread
  (:mod:`.intervals`) and judged by the modal-model check (:mod:`.modal_check`, on the H1's coherent
  lines, :mod:`armaxmodal.spectra`).
"""

from armaxmodal.modes.diagram import StabilisationDiagram, choose_nk, stabilisation_diagram
from armaxmodal.modes.modal_check import ModalCheck, check_modes
from armaxmodal.modes.pipeline import select_modes
from armaxmodal.modes.poles import Tolerances
from armaxmodal.modes.result import ModeSelection

__all__ = [
    "ModalCheck",
    "ModeSelection",
    "StabilisationDiagram",
    "Tolerances",
    "check_modes",
    "choose_nk",
    "select_modes",
    "stabilisation_diagram",
]
