"""The selection as it goes, and what every stage reads: ``SelectionState``, the one frozen
object each stage of ``select_modes`` takes and returns, and
``SelectionContext``, the diagram, band, orders and settings that stay the same from stage to
stage (:mod:`armaxmodal.modes.pipeline` names the stages)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from armaxmodal.quality_warnings import QualityWarning

if TYPE_CHECKING:  # types only: the stages that make them import this module
    from armaxmodal.modes.dft_model import ModalModel
    from armaxmodal.modes.diagram import StabilisationDiagram
    from armaxmodal.modes.modal_check import ModalCheck
    from armaxmodal.modes.mode_count import ModeCount
    from armaxmodal.modes.result import ModeSelection
    from armaxmodal.modes.settings import SelectionSettings

__all__ = ["SelectionContext", "SelectionState"]


@dataclass(frozen=True)
class SelectionState:
    """The modes selected so far and what the stages found about them.

    Attributes
    ----------
    modes : DataFrame
        One row per mode, by frequency: the columns of :attr:`armaxmodal.ModeSelection.modes`
        but the 95 % intervals, which are kept as their parts until the selection ends
        (:mod:`armaxmodal.modes.intervals`).
    shapes : (n_sensors, n_modes) complex ndarray
        The modal constants, one column per row of ``modes``.
    refinement : ModalModel or None
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
    picked : (DataFrame, list of ndarray) or None
        The picks' clusters as rows and shape vectors (``picks=``), taken before any fit.
    segment_fits : dict
        The segment refits of the representative orders, ``(orders, k) -> poles``, run beside the
        refit and read by the segment stage.
    doubts : tuple of (float, float, QualityWarning)
        The modes the measured FRF's check does not need, ``(Hz, ratio, note)``: out of the
        selection, offered to the count as candidates; a note stands where the count leaves it out.
    result : ModeSelection or None
        The finished selection; a stage that sets it ends the pipeline (a diagram with no mode).
    """

    modes: pd.DataFrame
    shapes: np.ndarray
    refinement: ModalModel | None = None
    check: ModalCheck | None = None
    count: ModeCount | None = None
    warnings: tuple[QualityWarning, ...] = ()
    check_poles: tuple[tuple[float, float], ...] | None = None
    picked: tuple[pd.DataFrame, list] | None = field(default=None, repr=False)
    segment_fits: dict = field(default_factory=dict, repr=False)
    doubts: tuple[tuple[float, float, QualityWarning], ...] = ()
    result: ModeSelection | None = field(default=None, repr=False)

    def __post_init__(self):
        if self.shapes.shape[1] != len(self.modes):
            raise ValueError(f"{len(self.modes)} modes but {self.shapes.shape[1]} shape columns")

    @classmethod
    def empty(cls, n_sensors: int) -> SelectionState:
        """The state before any stage: no mode."""
        return cls(pd.DataFrame(), np.zeros((n_sensors, 0), dtype=complex))

    def kept(self, rows) -> SelectionState:
        """Only the modes at positions ``rows`` (in that order), renumbered from 0."""
        rows = list(rows)
        return replace(self, modes=self.modes.iloc[rows].reset_index(drop=True), shapes=self.shapes[:, rows])

    def with_modes(self, modes: pd.DataFrame, shapes: np.ndarray, **changes) -> SelectionState:
        """Other modes (and any other attribute by keyword)."""
        return replace(self, modes=modes, shapes=shapes, **changes)

    def warned(self, *warnings: QualityWarning, **changes) -> SelectionState:
        """``warnings`` appended (and any other attribute by keyword)."""
        return replace(self, warnings=self.warnings + tuple(warnings), **changes)


@dataclass(frozen=True)
class SelectionContext:
    """What every stage reads and none changes.

    Attributes
    ----------
    diagram : StabilisationDiagram
    settings : SelectionSettings
        Every threshold of the selection (:mod:`armaxmodal.modes.settings`).
    band : (float, float) or None
        The user's band (Hz), or the diagram's.
    nas : list of int
        The diagram's orders, sorted.
    n_modes : int or None
        The number of modes asked for (the ``fixed count`` stages).
    picks : (n_picks,) ndarray or None
        The checked picks (Hz).
    segments : int
        Disjoint segments of the segment spread (0: none).
    refine : bool
        Whether the frequency-domain refit is made (the FRF screen refits again after additions).
    n_jobs : int or None
        Worker threads.
    bar : tqdm or None
        The progress bar that counts the selection's fits.
    on_stage : callable or None
        Called with each stage's name as it is entered (the progress bar's label; a test's trace).
    """

    diagram: StabilisationDiagram
    settings: SelectionSettings
    band: tuple[float, float] | None
    nas: list[int]
    n_modes: int | None = None
    picks: np.ndarray | None = None
    segments: int = 3
    refine: bool = True
    n_jobs: int | None = None
    bar: Any = field(default=None, repr=False)
    on_stage: Callable[[str], None] | None = field(default=None, repr=False)

    @property
    def orders(self) -> dict:
        """``{na: Orders}`` of the diagram."""
        return {o.na: o for o in self.diagram.orders}

    def update_bar(self, n: int) -> None:
        """Count ``n`` fits on the progress bar, if there is one."""
        if self.bar is not None and n:
            self.bar.update(n)
