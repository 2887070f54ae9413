"""The selection as it goes: one object that every stage of :func:`armaxmodal.select_modes`
takes and returns, instead of tuples of its parts whose length changed from stage to stage."""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from armaxmodal.quality_warnings import QualityWarning

if TYPE_CHECKING:  # types only: the stages that make them import this module
    from armaxmodal.modes.modal_check import ModalCheck
    from armaxmodal.modes.mode_count import ModeCount
    from armaxmodal.modes.refine import ModalRefinement

__all__ = ["WorkingSelection"]


@dataclass(frozen=True)
class WorkingSelection:
    """The modes selected so far and what the stages found about them.

    Attributes
    ----------
    modes : DataFrame
        One row per mode, by frequency: the columns of :attr:`armaxmodal.ModeSelection.modes`
        but the 95 % intervals, which are kept as their parts until the selection ends
        (:mod:`armaxmodal.modes.intervals`).
    shapes : (n_sensors, n_modes) complex ndarray
        The modal constants, one column per row of ``modes``.
    refinement : ModalRefinement or None
        The frequency-domain refit the values come from, once made.
    check : ModalCheck or None
        The modal-model check of ``modes``, once run (a stage that changes the modes runs it again).
    count : ModeCount or None
        The maximum-likelihood count, once run.
    warnings : tuple of QualityWarning
        What the stages said, in order.
    check_poles : tuple of (float, float) or None
        The poles the check fits, ``(Hz, ratio)``, where they are not the rows': the model's two
        poles of a pair the record does not separate, which one row reports. None: the rows'.
    """

    modes: pd.DataFrame
    shapes: np.ndarray
    refinement: ModalRefinement | None = None
    check: ModalCheck | None = None
    count: ModeCount | None = None
    warnings: tuple[QualityWarning, ...] = ()
    check_poles: tuple[tuple[float, float], ...] | None = None

    def __post_init__(self):
        if self.shapes.shape[1] != len(self.modes):
            raise ValueError(f"{len(self.modes)} modes but {self.shapes.shape[1]} shape columns")

    def kept(self, rows) -> WorkingSelection:
        """Only the modes at positions ``rows`` (in that order), renumbered from 0."""
        rows = list(rows)
        return replace(self, modes=self.modes.iloc[rows].reset_index(drop=True), shapes=self.shapes[:, rows])

    def with_modes(self, modes: pd.DataFrame, shapes: np.ndarray, **changes) -> WorkingSelection:
        """Other modes (and any other attribute by keyword)."""
        return replace(self, modes=modes, shapes=shapes, **changes)

    def warned(self, *warnings: QualityWarning, **changes) -> WorkingSelection:
        """``warnings`` appended (and any other attribute by keyword)."""
        return replace(self, warnings=self.warnings + tuple(warnings), **changes)
