"""Preparation of a record before any fit, and every data-quality check.

* :func:`prepare` -- checks, level shifts, detrending, alignment of late channels and
  resampling to the analysis band; :class:`Preparation` says what was done.
* :func:`check_quality` -- the pre-fit checks (:mod:`.quality`, :mod:`.held`, :mod:`.units`).

The record's spectra are not this stage's: they are the record's own (:mod:`armaxmodal.spectra`,
:meth:`~armaxmodal.Recording.welch`), computed once and read by every stage.
"""

from armaxmodal.prepare.checks import check_quality
from armaxmodal.prepare.preparation import Preparation, prepare

__all__ = ["Preparation", "check_quality", "prepare"]
