"""One model, not a sweep (thesis Section 3.3.2): the ``identify`` command's stage.

* :func:`~armaxmodal.identify` -- one shared-pole ARMAX model at orders given or chosen by an
  information criterion, its physical modes, their shapes and the modal-model check of
  :mod:`armaxmodal.modes` (:mod:`.one_model`).

It sits above ``modes/`` and uses its pole table, check and notes; the diagnosis loop builds on
it for its baseline orders.
"""

from armaxmodal.identification.one_model import Identification, identify

__all__ = ["Identification", "identify"]
