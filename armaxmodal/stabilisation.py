"""Stabilisation diagram and automatic mode selection (thesis Sections 3.3.2 and 3.4).

The model order is unknown: too low misses modes, too high adds spurious poles. The sweep
fits the shared-pole model (the default source of modes) and every sensor alone for
``na`` over a range, with the documented rules ``nb = na + 1 - nk`` and ``nc = na``, and one
input delay ``nk`` chosen by BIC at a middle order. Physical poles stay put as the order
grows; each pole is classed against the nearest pole of the previous order of the same
source: ``new``, ``f`` (frequency within ``tol_freq``), ``f+d`` (and damping within
``tol_damping``), ``f+d+v`` (and the mode-shape vector or residue within ``tol_shape``).

:func:`select_modes` then clusters the stable shared-pole estimates across orders, keeps the
clusters supported by a good share of the orders, and takes each cluster's medoid. It is
deterministic: the same data gives the same modes.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import partial

import numpy as np
import pandas as pd

from ._threads import one_blas_thread
from .disturbance import disturbance_lines
from .exceptions import OrderError
from .fit import ArmaxFit, _fit, fit_armax
from .frf import excited_band
from .frf_check import peak_support
from .modal import mode_record
from .modal_check import ModalCheck, check_modes
from .orders import _map, default_nb, default_nc, information_criterion
from .prepare import Preparation, oversampling_note, prepare
from .quality import QualityWarning
from .recording import Recording
from .refine import ModalRefinement, refine_modes
from .spread import N_SEGMENTS, apply_segment_spread, segment_jobs, segment_poles, segment_spread, split_segments

__all__ = ["stabilisation_diagram", "StabilisationDiagram", "select_modes", "ModeSelection", "Tolerances"]

SHARED = "shared"
# A sweep fit stops when an iteration lowers the loss by less than this fraction (a tenth of
# its statistical resolution, 1/N, for records up to 10^4 samples): enough to place poles.
# The fits whose estimates are reported are finished to fit_armax's default criterion.
SWEEP_TOL = 1e-5
CLASSES = ("new", "f", "f+d", "f+d+v")
#: rejection reason of a pole whose damping estimate is not positive but whose 95 % interval
#: reaches above zero: a lightly damped mode the record cannot resolve in damping. Such poles
#: count towards a mode's support, never as its estimate (see :func:`select_modes`).
UNRESOLVED_DAMPING = "damping not resolved"
#: a finished fit's pole farther than this (relative frequency) is another pole, not this one finished
FINISHED_MAX_SHIFT = 0.05
#: input delays the sweep searches (non-causal taps for band-limited data)
NK_SEARCH = range(0, -7, -1)
#: when the best delay is the most non-causal searched, this many more are tried once
NK_EXTENSION = 3
#: iteration cap of the delay choice's fits; the sweep continues those of the chosen delay
DELAY_CHOICE_ITERATIONS = 8
#: samples the record must hold per parameter of one sensor's model (about 3 na + 1 - nk) at
#: the sweep's highest order: fewer, and the fits describe the noise (and take minutes each)
SAMPLES_PER_PARAMETER = 20
#: a clear, coherent FRF peak no selected mode explains takes a cluster of poles of at least
#: this many orders within this relative frequency of it, when the modal-model check needs it
PEAK_CLUSTER_MIN_ORDERS = 2
PEAK_CLUSTER_FREQ = 0.03
#: a left-out cluster away from any peak must lie below this fraction of the input's band: at
#: its edge the input's power falls away and the H1's bias grows. The clusters the check
#: took there were at 0.97-0.98 of it (the F-16 level 5's 14.66 Hz, damping 0.19; a study
#: sweep's 19.36 Hz); a real heavily damped mode at 0.90 (the chain with feet's 24.8 Hz)
EDGE_FRACTION = 0.95
#: a candidate pole this close (relative frequency) to a selected mode is that mode
DUPLICATE_FREQ = 0.01
#: the orders swept when none are given, capped at what the record supports
DEFAULT_ORDERS = range(2, 31, 2)
#: a default sweep capped below this top order has too few orders to show stability: refused
MIN_DEFAULT_TOP = 8


@dataclass(frozen=True)
class Tolerances:
    """Stability tolerances between consecutive orders and the pole-rejection rules."""

    freq: float = 0.01  #: relative frequency change
    damping: float = 0.05  #: relative damping change
    shape: float = 0.02  #: 1 - MAC for shared shapes; relative residue change per sensor
    max_damping: float = 0.6  #: heavier damping is not a vibration mode here
    min_freq_hz: float | None = None  #: default: 3 / record length
    max_freq_fraction: float = 0.45  #: of fs; poles near Nyquist are filter artefacts
    min_energy: float = 0.01  #: residue energy relative to the largest pole at that order (lower it
    #: to keep weakly excited modes; 0.1 % admits weak extra poles on real and band-limited data)
    min_input_db: float = -30.0  #: input PSD below this (dB re its peak): no excitation there


@dataclass(frozen=True)
class StabilisationDiagram:
    """Poles of every order and source.

    Attributes
    ----------
    poles : DataFrame
        One row per pole: source (``shared`` or a sensor), na, freq_hz, damping,
        damped_freq_hz, freq_sd, damping_sd, energy (residue energy), cls (stability class),
        rejected (reason, empty when kept), pole (complex), vector (complex shape over
        sensors for shared poles; the residue for a sensor's own pole).
    orders : list of (na, nb, nc, nk)
    tolerances : Tolerances
    recording : Recording
        The record the sweep fitted (after :func:`armaxmodal.prepare.prepare`).
    preparation : Preparation or None
        What was done to the record first, with the quality warnings.
    """

    poles: pd.DataFrame
    orders: list
    tolerances: Tolerances
    recording: Recording
    fits: dict = field(repr=False, default_factory=dict)
    preparation: Preparation | None = None
    notes: tuple = ()

    @property
    def warnings(self) -> list[QualityWarning]:
        """Data-quality findings of the preparation and of the sweep itself."""
        found = list(self.preparation.warnings) if self.preparation is not None else []
        found += list(self.notes)
        found += _nk_edge_warning(self.orders[0][3], self.recording)
        return found + disturbance_lines(self.poles, self.tolerances.min_energy, self.recording, SHARED)

    def to_frame(self) -> pd.DataFrame:
        """The tidy pole table without the complex columns (for CSV)."""
        return self.poles.drop(columns=["pole", "vector"])

    def plot(self, selection=None, ax=None):
        from .plot import plot_stabilisation

        return plot_stabilisation(self, selection, ax=ax)


def _mac(a: np.ndarray, b: np.ndarray) -> float:
    den = np.vdot(a, a).real * np.vdot(b, b).real
    return float(abs(np.vdot(a, b)) ** 2 / den) if den > 0 else 0.0


_POLE_COLUMNS = [
    "source", "na", "freq_hz", "damping", "damped_freq_hz", "freq_sd", "damping_sd", "freq_ci95_lo",
    "freq_ci95_hi", "damping_ci95_lo", "damping_ci95_hi", "energy", "pole", "vector",
]  # fmt: skip


def _poles_of(fit: ArmaxFit, source: str) -> list[dict]:
    """Rows for one fit: shared fit -> one source with shapes over sensors."""
    rows = []
    if source == SHARED:
        table = fit.modes()
        frame = table[table.sensor == fit.sensors[0]]  # not query(): sensor names are free text
        mu = frame.pole.to_numpy()
        shapes = np.array([m.modal_constants(mu)[0] for m in fit.models]) if mu.size else np.zeros((0, 0))
        for i, r in enumerate(frame.itertuples(index=False)):
            rows.append(_row(source, fit, r, shapes[:, i], float(np.linalg.norm(shapes[:, i] * r.freq_hz))))
        return rows
    frame = fit.modes()
    mu = frame.pole.to_numpy()
    consts = fit.models[0].modal_constants(mu)[0] if mu.size else np.zeros(0)
    for i, r in enumerate(frame.itertuples(index=False)):
        rows.append(_row(source, fit, r, np.array([consts[i]]), float(abs(consts[i]) * r.freq_hz)))
    return rows


def _row(source, fit, r, shape, energy):
    return {
        "source": source,
        "na": fit.orders[0],
        "freq_hz": r.freq_hz,
        "damping": r.damping,
        "damped_freq_hz": r.damped_freq_hz,
        "freq_sd": r.freq_sd,
        "damping_sd": r.damping_sd,
        "freq_ci95_lo": r.freq_ci95_lo,
        "freq_ci95_hi": r.freq_ci95_hi,
        "damping_ci95_lo": r.damping_ci95_lo,
        "damping_ci95_hi": r.damping_ci95_hi,
        "energy": energy,
        "pole": r.pole,
        "vector": shape,
    }


def _fit_job(recording: Recording, job, max_iter: int, tol: float, covariance: bool = True):
    """``(fit, checkpoint)`` of a sweep job ``(source, orders[, checkpoint])``: the shared
    fit continues the checkpoint when there is one; ``(None, None)`` when the record cannot
    support the orders."""
    source, orders = job[:2]
    rec = recording if source == SHARED else recording.select([source])
    try:
        return _fit(
            rec, orders, shared_poles=source == SHARED, max_iter=max_iter, tol=tol, stop="decrease", warn=False,
            resume=job[2] if len(job) > 2 else None, covariance=covariance,
        )  # fmt: skip
    except OrderError:
        return None, None


def _fit_and_poles(recording: Recording, job, max_iter: int, tol: float):
    """A sweep job run in a worker: the fit and its pole rows (computing the rows there
    keeps the parent's serial share small)."""
    fit = _fit_job(recording, job, max_iter, tol)[0]
    return fit, ([] if fit is None else _poles_of(fit, job[0]))


def _job_cost(job, n_sensors: int) -> float:
    """Relative run time of a sweep fit: about linear in na and in the number of sensors."""
    source, orders = job[:2]
    return orders[0] * (n_sensors if source == SHARED else 1)


def choose_nk(recording: Recording, nk_values=range(0, -7, -1), na_values=(8, 10, 12), n_jobs=None) -> int:
    """The input delay of the lowest-BIC shared-pole model over a few middle orders.

    The delay and the order interact (band-limited data trade non-causal taps for poles), so
    they are chosen jointly; one order alone can pick a delay that biases heavily damped modes.
    """
    return _choose_nk(recording, nk_values, na_values, n_jobs)[0]


def _choose_nk(recording, nk_values, na_values, n_jobs, tol=SWEEP_TOL, extend=True):
    """``(nk, {(SHARED, orders): checkpoint})``: the chosen delay and where its fits stopped,
    which the sweep continues instead of fitting those orders again."""
    jobs = [(SHARED, (na, default_nb(na, nk), default_nc(na), nk)) for na in na_values for nk in nk_values]
    # BIC differences between delays are large; 8 iterations settle the choice (checked on
    # every fixture, a lightly damped structure and the real recordings against 20 and 50).
    # Only the criterion is needed here: no covariances.
    fits = _map(
        partial(_fit_job, recording, max_iter=DELAY_CHOICE_ITERATIONS, tol=tol, covariance=False),
        jobs,
        n_jobs,
        cost=partial(_job_cost, n_sensors=len(recording.sensors)),
    )
    scores = [information_criterion(f) if f is not None else np.inf for f, _ in fits]
    nk = int(jobs[int(np.argmin(scores))][1][3])
    if extend and nk == min(nk_values):
        # the best delay is the most non-causal one searched: look NK_EXTENSION further, once
        return _choose_nk(recording, range(nk, nk - NK_EXTENSION - 1, -1), na_values, n_jobs, tol, extend=False)
    return nk, {job: ck for job, (_, ck) in zip(jobs, fits, strict=True) if job[1][3] == nk and ck is not None}


def stabilisation_diagram(
    recording: Recording,
    orders=None,
    *,
    band: tuple[float, float] | None = None,
    detrend: str = "mean",
    resample: bool = True,
    align: bool = True,
    prepared: bool = False,
    nk: int | None = None,
    per_sensor: bool = True,
    per_sensor_max_order: int = 20,
    tolerances: Tolerances | None = None,
    max_iter: int = 30,
    tol: float = SWEEP_TOL,
    n_jobs: int | None = None,
    progress: bool = False,
) -> StabilisationDiagram:
    """Sweep the model order and class every pole.

    Parameters
    ----------
    recording : Recording
    orders : iterable of int, optional
        The ``na`` values; ``nb`` and ``nc`` follow the module's rules. Orders given are
        refused when the record cannot support the highest; the default,
        :data:`DEFAULT_ORDERS`, is capped at what the record supports (``orders_capped``).
    band : (lo, hi), optional
        Frequency band of interest, Hz: sets the analysis rate and, in :func:`select_modes`,
        the band modes are taken from.
    detrend, resample, align
        Preparation of the record (:func:`armaxmodal.prepare.prepare`): remove each
        channel's mean (or ``"linear"`` trend, or ``"none"``), resample a record sampled far
        above its band, align channels late by whole samples.
    prepared : bool
        The record is already prepared: fit it as it is (no checks, no warnings).
    nk : int, optional
        Input delay; by default chosen by BIC (:func:`choose_nk`).
    per_sensor : bool
        Also sweep every sensor alone (the thesis's per-sensor view, Table 3.2).
    per_sensor_max_order : int
        Highest ``na`` of the single-sensor sweeps.
    tolerances : Tolerances, optional
    max_iter : int
        Levenberg-Marquardt cap per fit (a sweep needs positions, not the last digit).
    tol : float
        Relative loss decrease at which a sweep fit stops; looser than :func:`fit_armax`'s
        default for the same reason. :func:`select_modes` finishes the fits it reports.
    n_jobs : int, optional
        Worker processes (default: all cores).
    progress : bool
        Show a progress bar.
    """
    with one_blas_thread():  # a with block, not a decorator: mutmut skips decorated functions
        limits = tolerances or Tolerances()
        preparation = None
        if not prepared:
            preparation = prepare(recording, band=band, detrend=detrend, resample=resample, align=align)
            recording = preparation.recording
        notes: tuple = ()
        if orders is None:
            orders, notes = _default_orders(recording, preparation)
        _check_top_order(max(orders), recording, preparation)
        known: dict = {}
        if nk is None:
            nk, known = _choose_nk(recording, NK_SEARCH, (8, 10, 12), n_jobs, tol)
        sources = [SHARED] + (list(recording.sensors) if per_sensor else [])
        order_list = [(na, default_nb(na, nk), default_nc(na), nk) for na in orders]
        # single sensors cannot support high orders (their bounds are wide): stop them earlier
        jobs = [(s, o) for o in order_list for s in sources if s == SHARED or o[0] <= per_sensor_max_order]
        # the delay choice's fits of these orders continue from where they stopped, exactly
        # as if fitted here from the start (unless this sweep's cap is below theirs)
        if max_iter < DELAY_CHOICE_ITERATIONS:
            known = {}
        todo = [job + ((known[job],) if job in known else ()) for job in jobs]
        from tqdm import tqdm

        with tqdm(total=len(jobs), desc="stabilisation sweep", unit="fit", disable=not progress) as bar:
            fitted = _map(
                partial(_fit_and_poles, recording, max_iter=max_iter, tol=tol),
                todo,
                n_jobs,
                bar,
                cost=partial(_job_cost, n_sensors=len(recording.sensors)),
            )
        done = dict(zip(jobs, fitted, strict=True))
        rows, kept = [], {}
        for source, o in jobs:
            fit, fit_rows = done[(source, o)]
            if fit is None:
                continue
            kept[(source, o[0])] = fit
            rows += fit_rows
        if not rows:
            raise OrderError("no order in the sweep could be fitted; use lower orders or a longer record.")
        poles = pd.DataFrame(rows)
        poles["cls"] = _classify(poles, limits)
        poles["rejected"] = _reject(poles, limits, recording)
        return StabilisationDiagram(poles, order_list, limits, recording, kept, preparation, notes)


def _supported_top_order(recording: Recording) -> int:
    """The highest ``na`` whose per-sensor model (``3 na + 1 - nk`` parameters at the most
    non-causal delay searched) has :data:`SAMPLES_PER_PARAMETER` samples a parameter."""
    return (recording.n_samples // SAMPLES_PER_PARAMETER - 1 + min(NK_SEARCH) - NK_EXTENSION) // 3


def _default_orders(recording: Recording, preparation: Preparation | None) -> tuple[list, tuple]:
    """:data:`DEFAULT_ORDERS`, capped at what the record supports (the user typed none, so a
    short record is no error of theirs) with an ``orders_capped`` note; uncapped when the
    record supports them all. Below :data:`MIN_DEFAULT_TOP` the sweep is refused as usual."""
    top = _supported_top_order(recording)
    if top >= max(DEFAULT_ORDERS):
        return list(DEFAULT_ORDERS), ()
    if top < MIN_DEFAULT_TOP:
        return list(DEFAULT_ORDERS), ()  # refused by _check_top_order, with its advice
    capped = [na for na in DEFAULT_ORDERS if na <= top]
    note = QualityWarning(
        "orders_capped", (),
        f"the default orders 2-{max(DEFAULT_ORDERS)} were capped at na = {max(capped)}: this record "
        f"({recording.n_samples} samples at {recording.fs:g} Hz) supports at most na = {top} "
        f"({SAMPLES_PER_PARAMETER} samples a parameter); a longer record allows higher orders",
        float(max(capped)),
    )  # fmt: skip
    return capped, (note,)


def _check_top_order(na: int, recording: Recording, preparation: Preparation | None) -> None:
    """Refuse, before any fit, a sweep whose highest order the record cannot support."""
    per_sensor = 3 * na + 1 - (min(NK_SEARCH) - NK_EXTENSION)
    if per_sensor * SAMPLES_PER_PARAMETER <= recording.n_samples:
        return
    top = max(_supported_top_order(recording), 2)
    narrow = [w for w in (preparation.warnings if preparation else ()) if w.code == "narrowband_input"]
    resampled = preparation is not None and preparation.analysis_fs != preparation.original_fs
    record = f"{recording.n_samples} samples at {recording.fs:g} Hz" + (
        f", resampled from {preparation.original_fs:g} Hz to the "
        + ("band" if preparation.band is not None else "input's band")
        if resampled
        else ""
    )
    lead = f"{narrow[0].message.rstrip('.')}; check that the input excites the structure. " if narrow else ""
    raise OrderError(
        f"{lead}Orders up to na = {na} need about {per_sensor} parameters per sensor; this record ({record}) "
        f"supports at most na = {top} ({SAMPLES_PER_PARAMETER} samples a parameter). Lower the top order, "
        f"e.g. --orders 2:{min(top, 40)}."
    )


def _nk_edge_warning(nk: int, recording: Recording) -> list[QualityWarning]:
    """The BIC-chosen delay at the most non-causal end of its search range: the data may
    need more (an input that lags the outputs)."""
    edge = min(NK_SEARCH) - NK_EXTENSION
    if nk > edge:
        return []
    return [
        QualityWarning(
            "nk_at_search_edge",
            (recording.input_name,),
            f"the chosen input delay nk = {nk} sits at the edge of its search range "
            f"({edge} to {max(NK_SEARCH)}): the outputs may lead the input by more (a late input "
            "or a filter delay); look at the sensor_delay check and align the channels.",
            float(nk),
        )
    ]


def _classify(poles: pd.DataFrame, tol: Tolerances) -> list[str]:
    cls = ["new"] * len(poles)
    for _source, group in poles.groupby("source", sort=False):
        by_order = {na: g for na, g in group.groupby("na")}
        nas = sorted(by_order)
        for prev, cur in zip(nas[:-1], nas[1:], strict=True):
            p = by_order[prev]
            for idx, row in by_order[cur].iterrows():
                rel = np.abs(p.freq_hz.values - row.freq_hz) / row.freq_hz
                j = int(np.argmin(rel))
                if rel[j] > tol.freq:
                    continue
                label = "f"
                prev_row = p.iloc[j]
                if abs(prev_row.damping - row.damping) <= tol.damping * max(abs(row.damping), 1e-3):
                    label = "f+d"
                    if row.vector.size > 1:
                        same_shape = 1 - _mac(row.vector, prev_row.vector) <= tol.shape
                    else:
                        same_shape = abs(abs(row.vector[0]) / max(abs(prev_row.vector[0]), 1e-300) - 1) <= 5 * tol.shape
                    if same_shape:
                        label = "f+d+v"
                cls[poles.index.get_loc(idx)] = label
    return cls


def _reject(poles: pd.DataFrame, tol: Tolerances, recording: Recording) -> list[str]:
    f_min = tol.min_freq_hz if tol.min_freq_hz is not None else 3.0 / recording.duration
    f_max = tol.max_freq_fraction * recording.fs
    band_lo, band_hi = excited_band(recording, tol.min_input_db)
    top = poles.groupby(["source", "na"]).energy.transform("max")
    reasons = []
    for row, e_max in zip(poles.itertuples(index=False), top, strict=True):
        if row.damping <= 0:
            sd = getattr(row, "damping_sd", 0.0)
            reasons.append(UNRESOLVED_DAMPING if row.damping + 1.96 * sd > 0 else "negative damping")
        elif row.damping > tol.max_damping:
            reasons.append("over-damped")
        elif row.freq_hz < f_min:
            reasons.append("near 0 Hz")
        elif row.freq_hz > f_max:
            reasons.append("near Nyquist")
        elif row.freq_hz > band_hi * (1 + row.damping) or row.freq_hz < band_lo * (1 - row.damping):
            reasons.append("no input energy")
        elif row.energy < tol.min_energy * e_max:
            reasons.append("negligible residue")
        else:
            reasons.append("")
    return reasons


# -- automatic selection -----------------------------------------------------------------------
@dataclass(frozen=True)
class ModeSelection:
    """Physical modes picked from a stabilisation diagram.

    Attributes
    ----------
    modes : DataFrame
        One row per mode, by frequency: freq_hz, damping, damped_freq_hz and 95 % intervals
        (from the representative fit), na of that fit, count and support of the cluster,
        its spread (standard deviation over orders) and medoid.
    shapes : (n_sensors, n_modes) complex ndarray
        EPFRF modal constants per sensor (Eq. 3.24) from the representative fit.
    per_sensor : DataFrame
        Table 3.2 form: one row per sensor and mode with the sensor's own frequency, damping
        and residue magnitude, NaN where the sensor does not show the mode (the thesis's X).
    weighted : DataFrame
        Eqs. 3.35-3.36: per mode, the |M_ij|-weighted mean of the per-sensor values.
    diagram : StabilisationDiagram
    refinement : ModalRefinement or None
        The frequency-domain refit (:mod:`armaxmodal.refine`); its ``hold`` is the
        inter-sample behaviour the data chose. ``modes.estimator`` says which values are
        reported: the refit for a band-limited recording, the ARMAX fit (the exact model
        class) for a held input.
    """

    modes: pd.DataFrame
    shapes: np.ndarray
    per_sensor: pd.DataFrame
    weighted: pd.DataFrame
    diagram: StabilisationDiagram
    refinement: ModalRefinement | None = None
    notes: tuple[QualityWarning, ...] = ()
    check: ModalCheck | None = None

    @property
    def reconstruction_error(self) -> float:
        """The modal-model check's relative misfit (:mod:`armaxmodal.modal_check`): the
        largest output's relative RMS difference between the measured H1 and its LSFD fit
        by the selected poles with residual terms and a delay. Computed once, in
        :func:`select_modes`: the CLI, the figure and the JSON report the same number."""
        return self.check.overall_error if self.check is not None else float("nan")

    @property
    def quality(self) -> str:
        """``"good"`` when the modal-model check passes, else ``"poor"``."""
        return "good" if self.check is not None and self.check.passed else "poor"

    @property
    def warnings(self) -> list[QualityWarning]:
        """The diagram's data-quality warnings and the selection's own."""
        return self.diagram.warnings + list(self.notes)

    def to_dict(self, shapes: str = "shared") -> dict:
        """The JSON contract of the ``stabilise`` command.

        ``shapes="shared"`` reports the shared-pole residues (complete by construction);
        ``"per_sensor"`` each sensor's own residue, with gaps filled by Eq. (3.34) and
        flagged ``supplemented``.
        """
        if shapes not in ("shared", "per_sensor"):
            raise ValueError(f"shapes: expected 'shared' or 'per_sensor', got {shapes!r}.")
        rec = self.diagram.recording
        if shapes == "shared":
            matrix, flags = self.shapes, np.zeros(self.shapes.shape, dtype=bool)
        else:
            from .merge import supplement_shapes

            matrix, flags = supplement_shapes(self)
        modes = []
        for i, row in enumerate(self.modes.itertuples(index=False)):
            record = mode_record(row, matrix[:, i], rec.sensors, flags[:, i])
            record.update(
                orders_supporting=int(row.count),
                freq_spread_hz=float(row.freq_spread),
                damping_spread=float(row.damping_spread),
            )
            if "segments_found" in self.modes:
                record["segment_spread"] = {
                    "segments_found": int(row.segments_found),
                    "freq_sd_hz": _finite_or_none(row.freq_segment_sd),
                    "damping_sd": _finite_or_none(row.damping_segment_sd),
                }
                record["model_error_dominates"] = bool(row.model_error_dominates)
            modes.append(record)
        per_sensor = [
            {k: (None if isinstance(v, float) and np.isnan(v) else v) for k, v in r.items()}
            for r in self.per_sensor.drop(columns=["own_modal_constant"]).to_dict("records")
        ]
        t = self.diagram.tolerances
        prep = self.diagram.preparation
        return {
            "fs": rec.fs if prep is None else prep.original_fs,
            "analysis_fs": rec.fs,
            "preprocessing": None if prep is None else prep.to_dict(),
            "warnings": [w.to_dict() for w in self.warnings],
            "input": rec.input_name,
            "outputs": list(rec.sensors),
            "nk": self.diagram.orders[0][3],
            "orders_na": [o[0] for o in self.diagram.orders],
            "tolerances": {"freq": t.freq, "damping": t.damping, "shape": t.shape, "max_damping": t.max_damping},
            "quality": self.quality,
            "reconstruction_error": _finite_or_none(self.reconstruction_error),
            "modal_check": None if self.check is None else self.check.to_dict(),
            "intersample_hold": None if self.refinement is None else self.refinement.hold,
            "estimator": sorted(set(self.modes.estimator)),
            "modes": modes,
            "per_sensor": per_sensor,
        }


def select_modes(
    diagram: StabilisationDiagram,
    n_modes: int | None = None,
    band: tuple[float, float] | None = None,
    *,
    min_support: float = 0.4,
    cluster_freq: float = 0.05,
    cluster_damping: float = 0.5,
    merge_mac: float = 0.8,
    refine: bool = True,
    segments: int = N_SEGMENTS,
    n_jobs: int | None = None,
) -> ModeSelection:
    """Pick the physical modes from the shared-pole poles of a diagram.

    Kept, non-rejected poles are clustered across orders (greedy, in order of increasing
    ``na``; a pole joins the nearest cluster whose median lies within ``cluster_freq``
    relative frequency and ``cluster_damping`` relative damping and which has no pole of that
    order yet). A cluster is a mode when it holds poles of at least ``min_support`` of the
    swept orders. Each mode is reported from the
    fit of lowest BIC among the orders in its cluster -- the most parsimonious adequate model;
    over-parameterised orders scatter heavily damped modes -- with the cluster's medoid,
    spread and count alongside. Two modes closer than the half-power bandwidth of the
    better-supported one (``2 xi f``) whose shapes agree (MAC >= ``merge_mac``) are one mode
    split by over-modelling; the weaker is dropped.

    Parameters
    ----------
    diagram : StabilisationDiagram
    n_modes : int, optional
        Keep the ``n_modes`` best-supported modes (the modal-model check then judges them but
        neither drops nor adds any).
    band : (lo, hi), optional
        Frequency band in Hz (default: the diagram's band, if it was given one).
    refine : bool
        Refit the selected modes to the recording's DFT under the inter-sample behaviour the
        data choose (:func:`armaxmodal.refine.refine_modes`) and report the refit when the
        recording is band-limited, where the discrete ARMAX class is biased.
    segments : int
        Refit each mode's representative orders on this many disjoint segments and widen
        the intervals where their spread exceeds them (:mod:`armaxmodal.spread`); 0 skips.
    n_jobs : int, optional
        Worker processes for the finishing and segment fits (default: all cores; 1 inside a
        process that may not start its own, e.g. a dask worker).
    """
    with one_blas_thread():
        if band is None and diagram.preparation is not None:
            band = diagram.preparation.band
        nas = sorted({o[0] for o in diagram.orders})
        modes, vectors = _clustered_modes(diagram, band, nas, min_support, cluster_freq, cluster_damping, n_jobs)
        if not modes.empty:
            keep = _merge_duplicates(modes, vectors, merge_mac, diagram.recording.duration)
            modes, vectors = modes.loc[keep].reset_index(drop=True), [vectors[i] for i in keep]
        if modes.empty:
            raise OrderError(
                "no stable mode found"
                + (f" in {band[0]:g}-{band[1]:g} Hz" if band else "")
                + "; widen the band, extend the order range, or check that the input excites the structure."
            )
        order = modes.sort_values(["support", "count", "energy"], ascending=False).index
        if n_modes is not None:
            order = order[:n_modes]
        order = modes.loc[order].sort_values("freq_hz").index
        modes = modes.loc[order].reset_index(drop=True)
        shapes = np.column_stack([vectors[i] for i in order])
        modes["estimator"] = "armax"
        # the segment refits are ARMAX fits: their spread is judged against the ARMAX intervals
        modes["freq_sd_armax"] = (modes.freq_ci95_hi - modes.freq_ci95_lo) / (2 * 1.96)
        modes["damping_sd_armax"] = (modes.damping_ci95_hi - modes.damping_ci95_lo) / (2 * 1.96)
        refinement = None
        orders = {o[0]: o for o in diagram.orders}
        fitted = _refit_and_segment_fits(diagram, modes, band, refine, segments, orders, n_jobs)
        if refine:
            refit, limits = fitted.pop("refit"), (cluster_freq, cluster_damping, merge_mac)
            modes, shapes, refinement = _refined(diagram, modes, shapes, refit, *limits)
        if n_modes is None:
            modes, shapes, notes, check = _modes_the_record_needs(diagram.recording, modes, shapes, band)
            clustering, n_before = (cluster_freq, cluster_damping), len(modes)
            modes, shapes, check = _modes_the_check_adds(diagram, modes, shapes, band, nas, check, clustering)
            if len(modes) > n_before:  # a mode the added ones make redundant goes (a merge of two)
                modes, shapes, more, check = _modes_the_record_needs(diagram.recording, modes, shapes, band)
                notes += more
            if refine and len(modes) > n_before:  # the refit saw fewer modes than are reported
                limits = (cluster_freq, cluster_damping, merge_mac)
                modes, shapes, refinement, check = _refit_with_added(diagram, modes, shapes, band, limits, refinement)
        else:  # the user fixed the number of modes: the check judges them, it does not choose
            notes, check = [], check_modes(diagram.recording, modes.freq_hz, modes.damping, band)
        if segments >= 2:
            orders_of = lambda i: orders[int(modes.at[i, "na"])]  # noqa: E731
            spread = segment_spread(diagram.recording, modes, orders_of, segments, n_jobs, fitted)
            modes, spread_notes = apply_segment_spread(modes, spread, segments)
            notes += spread_notes
        per_sensor, weighted = _per_sensor_table(diagram, modes, shapes, cluster_freq)
        from .frf_check import unexplained_peaks

        notes += unexplained_peaks(diagram.recording, modes.freq_hz.to_numpy(), modes.damping.to_numpy(), band)
        notes += oversampling_note(modes.freq_hz.to_numpy(), diagram.recording.fs)
        notes += _unresolved_damping_notes(modes, len(nas))
        notes += check.warnings()
        return ModeSelection(modes, shapes, per_sensor, weighted, diagram, refinement, tuple(notes), check)


def _clustered_modes(diagram, band, nas, min_support, cluster_freq, cluster_damping, n_jobs):
    """One mode per supported cluster (the kept poles', then the rescued lightly damped
    ones), each from its representative fit: ``(modes, shape vectors)``."""
    cand = _candidates(diagram.poles, band)
    clusters = _cluster(cand[cand.rejected == ""], nas, cluster_freq, cluster_damping)
    clusters = [c for c in clusters if _supported(len(c), len(nas), min_support)]
    left = cand.drop(index=[m for c in clusters for m in c])
    clusters += _rescued_clusters(diagram, left, nas, cluster_freq, min_support, band)
    bic = {na: information_criterion(fit) for (src, na), fit in diagram.fits.items() if src == SHARED}
    firsts = [_ranked(cand.loc[c][cand.loc[c].damping > 0], bic) for c in clusters]
    finished = _finish_fits(diagram, {ranked[0] for ranked in firsts if ranked}, n_jobs)
    rows, vectors = [], []
    for members in clusters:
        sub = cand.loc[members]
        rep = _representative(diagram, sub[sub.damping > 0], bic, finished)
        if rep is None:
            continue
        rows.append({**_mode_row(rep, sub, len(nas)), "orders_damping_unresolved": int((sub.damping <= 0).sum())})
        vectors.append(rep.vector)
    return pd.DataFrame(rows), vectors


def _representative(diagram, resolved: pd.DataFrame, bic: dict, finished: dict) -> pd.Series | None:
    """The cluster's pole from the fit of lowest BIC, finished to full convergence; the next
    order's when finishing takes a lightly damped pole's damping to zero or below (None when
    every one does: the record gives this mode no damping estimate)."""
    for na in _ranked(resolved, bic):
        rep = _finished_pole(diagram, resolved[resolved.na == na].iloc[0], finished)
        if rep.damping > 0:
            return rep
    return None


def _ranked(poles: pd.DataFrame, bic: dict) -> list[int]:
    """The orders of ``poles`` (one pole each), lowest BIC first."""
    return sorted((int(na) for na in poles.na), key=lambda na: (bic.get(na, np.inf), na))


def _finish_fits(diagram: StabilisationDiagram, nas, n_jobs: int | None) -> dict:
    """``{na: poles}`` of the shared fits of orders ``nas`` continued to :func:`fit_armax`'s
    default tolerance (the sweep stops its fits early), over the worker processes."""
    nas = sorted(nas)
    fits = [diagram.fits[(SHARED, na)] for na in nas]
    done = _map(partial(_finished_poles, diagram.recording), fits, n_jobs, cost=lambda fit: fit.orders[0], min_items=2)
    return dict(zip(nas, done, strict=True))


def _finished_poles(recording: Recording, fit: ArmaxFit) -> pd.DataFrame:
    done = fit_armax(recording, *fit.orders, shared_poles=True, max_iter=100, start=fit, warn=False)
    return pd.DataFrame(_poles_of(done, SHARED))


def _refit_and_segment_fits(diagram, modes, band, refine: bool, segments: int, orders: dict, n_jobs) -> dict:
    """The frequency-domain refit (key ``"refit"``) and the segment refits of every mode's
    representative orders (keys ``(orders, k)``), run together over the worker processes:
    the refit ran alone in this process before, while the workers waited."""
    jobs: list = [("refit", _refit_band(diagram.recording, band))] if refine else []
    if segments >= 2:
        jobs += [("segment", job) for job in segment_jobs(sorted({orders[int(na)] for na in modes.na}), segments)]
    parts = split_segments(diagram.recording, segments) if segments >= 2 else []
    task = partial(_selection_job, diagram.recording, parts, modes)
    # the refit first: it is the longest job (a frequency-domain fit of every mode)
    done = _map(task, jobs, n_jobs, cost=lambda job: np.inf if job[0] == "refit" else job[1][0][0], min_items=2)
    return {("refit" if kind == "refit" else job): result for (kind, job), result in zip(jobs, done, strict=True)}


def _refit_band(recording: Recording, band) -> tuple[float, float]:
    """Where the refit fits: the input's excited band, inside the user's band if given (modes
    outside it are not in the refit)."""
    lo, hi = excited_band(recording)
    return (lo, hi) if band is None else (max(lo, band[0]), min(hi, band[1]))


def _selection_job(recording: Recording, parts: list, modes: pd.DataFrame, job):
    kind, what = job
    if kind == "segment":
        return segment_poles(parts, what)
    try:
        return refine_modes(recording, modes.freq_hz, modes.damping, band_hz=what)
    except (OrderError, np.linalg.LinAlgError):
        return None  # too few lines or a degenerate basis: the ARMAX values stand


def _refined(diagram, modes, shapes, refinement, cluster_freq, cluster_damping, merge_mac, relaxed=False):
    """The frequency-domain refit (:func:`armaxmodal.refine.refine_modes`, or None when it
    could not be made), reported for a band-limited record; ``(modes, shapes, refinement)``.
    ``relaxed``: the refit may move a mode by :func:`_refit_reach`, not ``cluster_freq``."""
    if refinement is None:
        return modes, shapes, None
    if refinement.hold == "bandlimited":
        modes, shapes = _apply_refinement(modes, shapes, refinement, cluster_freq, cluster_damping, relaxed)
        # two modes the refit brought together are one peak
        keep = _merge_duplicates(modes, list(shapes.T), merge_mac, diagram.recording.duration)
        modes, shapes = modes.loc[keep].reset_index(drop=True), shapes[:, keep]
    return modes, shapes, refinement


def _modes_the_record_needs(recording: Recording, modes: pd.DataFrame, shapes: np.ndarray, band):
    """Selection by the data: drop, one at a time and least supported first, every mode the
    modal-model check does not need (:func:`armaxmodal.modal_check.mode_support`: leaving it
    out, a neighbour inside its half-power band refitted in its place, raises no output's
    misfit by :data:`~armaxmodal.modal_check.MODEL_ERROR_RISE` significantly). A dropped half
    of a split peak is a ``split_merged`` note, any other a ``mode_not_needed`` note.
    Returns ``(modes, shapes, notes, check)`` with the check of the modes kept."""
    from .modal_check import MODEL_ERROR_RISE, check_modes, mode_support

    notes: list[QualityWarning] = []
    while True:
        check = check_modes(recording, modes.freq_hz, modes.damping, band)
        if len(modes) < 2 or not np.isfinite(check.error).any():
            return modes, shapes, notes, check
        support = [mode_support(recording, modes.freq_hz, modes.damping, m, check, band) for m in range(len(modes))]
        weak = [m for m in range(len(modes)) if not support[m].needed]
        if not weak:
            return modes, shapes, notes, check
        # the least supported across orders goes first (of a split, the half the diagram
        # shows less), then the least needed
        rank = modes.sort_values(["support", "count", "energy"]).index.tolist()
        m = min(weak, key=lambda i: (rank.index(i), support[i].rise))
        s, f_m, x_m = support[m], modes.at[m, "freq_hz"], modes.at[m, "damping"]
        evidence = (
            f"without it no output's misfit rises by {100 * MODEL_ERROR_RISE:g} % "
            f"(at most {100 * s.rise:+.1f} %, p = {s.p_value:.2g})"
        )
        if s.refitted_neighbour is not None:
            f_n = modes.at[s.refitted_neighbour, "freq_hz"]
            notes.append(QualityWarning(
                "split_merged", (),
                f"modes at {f_n:.3f} and {f_m:.3f} Hz overlap within their half-power bands and the measured FRF does "
                f"not need both: {evidence} once {f_n:.3f} Hz may take the whole peak; one peak split by the model, "
                f"{f_n:.3f} Hz is reported", float(f_m),
            ))  # fmt: skip
        else:
            notes.append(QualityWarning(
                "mode_not_needed", (),
                f"a stable pole at {f_m:.3f} Hz (damping {x_m:.3f}) is left out: the measured FRF does not need it, "
                f"{evidence}: a spurious pole of the model (noise, a nonlinearity, leakage), not a mode of the record",
                float(f_m),
            ))  # fmt: skip
        keep = [i for i in range(len(modes)) if i != m]
        modes, shapes = modes.iloc[keep].reset_index(drop=True), shapes[:, keep]


def _refit_with_added(diagram, modes, shapes, band, limits, refinement):
    """The frequency-domain refit again, of every mode once the check has added some: a mode
    missing from a refit biases its neighbours (a five-segment chain's 13.5 Hz mode came out
    at 12.5 Hz while the 24.8 Hz one was missing, and its refit was refused as too far; now
    13.3 Hz for the exact 13.54). ``(modes, shapes, refinement, check)``."""
    from .modal_check import check_modes

    refit = _selection_job(diagram.recording, [], modes, ("refit", _refit_band(diagram.recording, band)))
    if refit is not None:  # the first refit's start lacked these modes: its refusals may not stand
        modes, shapes, refinement = _refined(diagram, modes, shapes, refit, *limits, relaxed=True)
    return modes, shapes, refinement, check_modes(diagram.recording, modes.freq_hz, modes.damping, band)


def _modes_the_check_adds(diagram, modes: pd.DataFrame, shapes: np.ndarray, band, nas, check, clustering):
    """Stable clusters the support rule left out enter when the modal-model check needs them
    (as :func:`_modes_the_record_needs` judges, but with the nearest mode refitted in its place,
    not only an overlapping one: one at a time, the largest first): the
    candidates are the cluster of poles of at least :data:`PEAK_CLUSTER_MIN_ORDERS` orders
    within :data:`PEAK_CLUSTER_FREQ` of each clear, coherent H1 peak no selected mode
    explains (:func:`armaxmodal.frf_check.unexplained_peaks`), and every cluster of kept
    poles of at least three orders away from the selected modes (heavily damped modes make
    no clear peak, and their poles scatter over the orders; these need a damping the record
    resolves, as a peak's cluster does not). A peak left unexplained is listed at the end as
    before. Returns ``(modes, shapes, check)``."""
    from .modal_check import check_modes, mode_support

    bic = {na: information_criterion(fit) for (src, na), fit in diagram.fits.items() if src == SHARED}
    for sub, at_peak in _left_out_clusters(diagram, modes, band, nas, clustering):
        # the cluster's centre is tried: its lowest-BIC pole may sit at its edge
        centre = float(sub.freq_hz.median()), float(sub.damping.median())
        if np.any(np.abs(modes.freq_hz.to_numpy() / centre[0] - 1) <= DUPLICATE_FREQ):
            continue  # a selected mode's own pole
        trial = np.r_[modes.freq_hz, centre[0]], np.r_[modes.damping, centre[1]]
        trial_check = check_modes(diagram.recording, *trial, band)
        if centre[0] in trial_check.unconfirmed_hz:
            continue  # no coherent line there: the check cannot judge it, so it cannot enter
        if not mode_support(diagram.recording, *trial, len(modes), trial_check, band, reach="nearest").needed:
            continue
        core = sub[np.abs(sub.freq_hz / centre[0] - 1) <= PEAK_CLUSTER_FREQ]  # reported from near the centre
        rep = _representative(diagram, core if len(core) else sub, bic, {})
        if rep is None or (not at_peak and not rep.damping_ci95_lo > 0):
            continue  # without a peak, a pole whose damping the record does not resolve is no evidence
        row = {**_mode_row(rep, sub, len(nas)), "orders_damping_unresolved": 0, "estimator": "armax"}
        row["freq_sd_armax"] = (row["freq_ci95_hi"] - row["freq_ci95_lo"]) / (2 * 1.96)
        row["damping_sd_armax"] = (row["damping_ci95_hi"] - row["damping_ci95_lo"]) / (2 * 1.96)
        modes = pd.concat([modes, pd.DataFrame([row])], ignore_index=True)
        shapes = np.column_stack([shapes, rep.vector])
        check = check_modes(diagram.recording, modes.freq_hz, modes.damping, band)
    order = modes.sort_values("freq_hz").index.tolist()
    return modes.loc[order].reset_index(drop=True), shapes[:, order], check


def _left_out_clusters(diagram, modes: pd.DataFrame, band, nas, clustering) -> list[tuple[pd.DataFrame, bool]]:
    """The candidate clusters of :func:`_modes_the_check_adds`, the largest first, each with
    whether it stands at an unexplained peak."""
    from .frf_check import unexplained_peaks

    cluster_freq, cluster_damping = clustering
    cand = _candidates(diagram.poles, band)
    cand = cand[cand.damping > 0]
    found = []
    for peak in unexplained_peaks(diagram.recording, modes.freq_hz.to_numpy(), modes.damping.to_numpy(), band):
        near = cand[np.abs(cand.freq_hz / peak.value - 1) <= PEAK_CLUSTER_FREQ]
        clusters = [c for c in _cluster(near, nas, PEAK_CLUSTER_FREQ, None) if len(c) >= PEAK_CLUSTER_MIN_ORDERS]
        if clusters:
            found.append((near.loc[max(clusters, key=len)], True))
    # away from a peak, a cluster in the top of the input's band is its edge's, not a mode
    top = EDGE_FRACTION * _refit_band(diagram.recording, band)[1]
    kept = cand[(cand.rejected == "") & (cand.freq_hz <= top)]
    selected = modes.freq_hz.to_numpy()
    for members in _cluster(kept, nas, cluster_freq, cluster_damping):
        sub = kept.loc[members]
        if len(members) >= 3 and np.min(np.abs(selected / sub.freq_hz.median() - 1)) > cluster_freq:
            found.append((sub, False))
    return sorted(found, key=lambda item: len(item[0]), reverse=True)


def _unresolved_damping_notes(modes: pd.DataFrame, n_orders: int) -> list[QualityWarning]:
    """A ``damping_unresolved`` note for every mode whose damping interval reaches zero or
    whose damping estimate is not positive at some orders of the sweep, with the reason."""
    notes = []
    for m in modes.itertuples(index=False):
        crossed = int(m.orders_damping_unresolved)
        if crossed == 0 and m.damping_ci95_lo > 0:
            continue
        facts = [f"damping {m.damping:.2g}, 95 % interval [{m.damping_ci95_lo:.2g}, {m.damping_ci95_hi:.2g}]"]
        if crossed:
            facts.append(f"its estimate is not positive at {crossed} of {n_orders} orders")
        if getattr(m, "model_error_dominates", False):
            why = ("the interval is the spread of the record's thirds (model_error_dominates): the thirds disagree "
                   "about this damping; run 'armaxmodal diagnose'")  # fmt: skip
        else:
            why = "the damping is below what this record resolves: a longer record, or more excitation here, narrows it"
        notes.append(QualityWarning(
            "damping_unresolved", (),
            f"mode at {m.freq_hz:.3f} Hz ([{m.freq_ci95_lo:.4g}, {m.freq_ci95_hi:.4g}] Hz): {'; '.join(facts)}. {why}",
            float(m.freq_hz),
        ))  # fmt: skip
    return notes


def _supported(count: int, n_orders: int, min_support: float) -> bool:
    """A cluster is a mode when it holds poles of at least three orders and ``min_support``
    of the swept ones."""
    return count >= 3 and count / n_orders >= min_support


def _candidates(poles: pd.DataFrame, band) -> pd.DataFrame:
    """Shared-pole poles that may form a mode: the kept ones and those whose damping the
    record does not resolve (they count towards support, see :func:`select_modes`)."""
    cand = poles[(poles.source == SHARED) & poles.rejected.isin(["", UNRESOLVED_DAMPING])]
    if band is not None:
        cand = cand[(cand.freq_hz >= band[0]) & (cand.freq_hz <= band[1])]
    return cand


def _cluster(cand: pd.DataFrame, nas, cluster_freq: float, cluster_damping: float | None) -> list[list[int]]:
    """Greedy clustering across orders (see :func:`select_modes`): lists of ``cand`` indices.
    ``cluster_damping=None`` groups by frequency alone."""
    clusters: list[list[int]] = []
    # per cluster: its orders and its median frequency and damping, updated as members join
    # (plain lists: per-element pandas lookups made this loop 0.25 s on a 20,000-sample record)
    orders: list[set] = []
    values: list[tuple[list, list]] = []
    centres: list[tuple[float, float]] = []
    for na in nas:
        group = cand[cand.na == na].sort_values("energy", ascending=False)
        for idx, freq, damping in zip(group.index, group.freq_hz.to_numpy(), group.damping.to_numpy(), strict=True):
            best, best_d = None, np.inf
            for ci, (f_c, x_c) in enumerate(centres):
                if na in orders[ci]:
                    continue
                df = abs(freq - f_c) / f_c
                dx = 0.0 if cluster_damping is None else abs(damping - x_c) / x_c
                if df <= cluster_freq and (cluster_damping is None or dx <= cluster_damping) and df + 0.1 * dx < best_d:
                    best, best_d = ci, df + 0.1 * dx
            if best is None:
                clusters.append([])
                orders.append(set())
                values.append(([], []))
                centres.append((freq, damping))
                best = len(clusters) - 1
            clusters[best].append(idx)
            orders[best].add(na)
            values[best][0].append(freq)
            values[best][1].append(damping)
            centres[best] = (float(np.median(values[best][0])), float(np.median(values[best][1])))
    return clusters


def _rescued_clusters(diagram, rest: pd.DataFrame, nas, cluster_freq: float, min_support: float, band) -> list:
    """Lightly damped modes the damping rule splits: poles the selection left, whose damping
    the record does not resolve (the 95 % interval reaches zero, or the estimate crosses it),
    grouped by frequency alone. A group is a mode when it has the usual support, a positive
    estimate at some order, and the measured FRF a clear, coherent peak there -- the data's
    own evidence, which noise poles lack."""
    light = rest[rest.damping - 1.96 * rest.damping_sd <= 0]
    found = []
    for members in _cluster(light, nas, cluster_freq, None):
        sub = light.loc[members]
        if not _supported(len(members), len(nas), min_support) or not (sub.damping > 0).any():
            continue
        if peak_support(diagram.recording, float(sub.freq_hz.median()), 0.0, band) is not None:
            found.append(members)
    return found


def _mode_row(rep: pd.Series, sub: pd.DataFrame, n_orders: int) -> dict:
    """One selected mode: the representative pole's estimate, the cluster's medoid and spread."""
    f, x = sub.freq_hz.to_numpy(), sub.damping.to_numpy()
    x_scale = max(abs(float(np.mean(x))), float(np.median(sub.damping_sd)), 1e-12)  # damping may cross zero
    dist = np.abs(f[:, None] - f[None]) / f.mean() + np.abs(x[:, None] - x[None]) / x_scale
    medoid = sub.iloc[int(np.argmin(dist.sum(axis=1)))]
    row = {k: rep[k] for k in _ESTIMATE_COLUMNS}
    row.update(
        na=int(rep.na),
        count=len(sub),
        support=len(sub) / n_orders,
        freq_spread=float(np.std(f, ddof=1)),
        damping_spread=float(np.std(x, ddof=1)),
        medoid_freq_hz=medoid.freq_hz,
        medoid_damping=medoid.damping,
        energy=float(sub.energy.median()),
    )
    return row


_ESTIMATE_COLUMNS = (
    "freq_hz", "damping", "damped_freq_hz", "freq_ci95_lo", "freq_ci95_hi", "damping_ci95_lo", "damping_ci95_hi",
)  # fmt: skip


def _finite_or_none(value) -> float | None:
    return float(value) if np.isfinite(value) else None


def _finished_pole(diagram: StabilisationDiagram, pole: pd.Series, cache: dict) -> pd.Series:
    """The pole as estimated by its order's fit continued to :func:`fit_armax`'s default
    tolerance (the sweep stops its fits early); ``cache`` holds the finished fits' poles."""
    na = int(pole.na)
    if na not in cache:
        cache[na] = _finished_poles(diagram.recording, diagram.fits[(SHARED, na)])
    poles = cache[na]
    if poles.empty:
        return pole
    nearest = poles.iloc[int(np.argmin(np.abs(poles.pole.to_numpy() - pole.pole)))]
    if abs(nearest.freq_hz / pole.freq_hz - 1) > FINISHED_MAX_SHIFT:
        return pole  # finishing moved this pole away (a weak one): the sweep's estimate stands
    # the finished estimate, with the diagram's own columns (class, rejection) kept
    return pd.concat([nearest, pole.drop(nearest.index, errors="ignore")])


def _refit_reach(freq_hz: np.ndarray, i: int, max_freq_change: float) -> float:
    """How far (relative frequency) the refit after added modes may move mode ``i``:
    ``max_freq_change``, or less than halfway to the nearest other mode if that is farther
    (at most twice ``max_freq_change``) -- a refit that stays nearer its own start than any
    other mode's has not jumped to another mode. (A heavily damped mode the ARMAX fits
    scatter over 12.2-14.0 Hz was refitted from 12.49 to 13.31 Hz, the exact 13.54 Hz, and
    refused by the 5 % rule alone. For every first refit the 5 % rule stays: relaxed there,
    it moved a study subject's 17.2 Hz mode to 16.1 Hz.)"""
    others = np.delete(freq_hz, i)
    half_gap = 0.5 * np.min(np.abs(others - freq_hz[i])) / freq_hz[i] if others.size else np.inf
    return max(max_freq_change, min(half_gap, 2 * max_freq_change))


def _apply_refinement(modes, shapes, ref, max_freq_change, max_damping_change, relaxed=False):
    """Report the band-limited refit of each mode unless it left the mode's neighbourhood
    (``max_freq_change``, or :func:`_refit_reach` when ``relaxed``, in frequency;
    ``max_damping_change`` in damping; then the ARMAX value stays and ``estimator`` says so)."""
    modes, shapes = modes.copy(), shapes.copy()
    for i in range(len(modes)):
        df = abs(ref.freq_hz[i] / modes.at[i, "freq_hz"] - 1)
        dx = abs(ref.damping[i] / modes.at[i, "damping"] - 1)
        reach = _refit_reach(modes.freq_hz.to_numpy(), i, max_freq_change) if relaxed else max_freq_change
        if df > reach or dx > max_damping_change:
            modes.at[i, "estimator"] = "armax (refit moved too far)"
            continue
        f, x = ref.freq_hz[i], ref.damping[i]
        modes.loc[i, ["freq_hz", "damping", "damped_freq_hz", "estimator"]] = [
            f,
            x,
            f * np.sqrt(1 - x**2),
            "fd-bandlimited",
        ]
        modes.loc[i, ["freq_ci95_lo", "freq_ci95_hi"]] = [f - 1.96 * ref.freq_sd[i], f + 1.96 * ref.freq_sd[i]]
        modes.loc[i, ["damping_ci95_lo", "damping_ci95_hi"]] = [
            x - 1.96 * ref.damping_sd[i],
            x + 1.96 * ref.damping_sd[i],
        ]
        shapes[:, i] = ref.shapes[:, i]
    return modes, shapes


def _merge_duplicates(modes: pd.DataFrame, vectors: list, merge_mac: float, duration_s: float) -> list[int]:
    """Indices of the modes to keep after merging split (near-duplicate) modes.

    A weaker mode is the better-supported one split by over-modelling when it lies within
    that mode's half-power bandwidth (``2 xi f``) with a similar shape (MAC >= ``merge_mac``),
    or, whatever its shape, within ``2 / duration_s`` of it: two frequencies that close cannot
    be told apart by a record of this length. (Heavily damped modes are often closer than
    their bandwidths -- the supine human's -- so the bandwidth alone decides nothing.)
    """
    ranked = modes.sort_values(["support", "count", "energy"], ascending=False).index
    kept: list[int] = []
    for i in ranked:
        if not any(_is_split(modes, vectors, i, j, merge_mac, duration_s) for j in kept):
            kept.append(i)
    return sorted(kept)


def _is_split(modes, vectors, i, j, merge_mac, duration_s) -> bool:
    """Mode ``i`` is mode ``j`` split in two (see :func:`_merge_duplicates`)."""
    gap = abs(modes.at[i, "freq_hz"] - modes.at[j, "freq_hz"])
    half_power = 2 * modes.at[j, "damping"] * modes.at[j, "freq_hz"]
    unresolvable = gap <= 2.0 / duration_s
    return unresolvable or (gap <= half_power and _mac(vectors[i], vectors[j]) >= merge_mac)


def _per_sensor_table(diagram, modes, shapes, cluster_freq):
    """Table 3.2 (per sensor, gaps as NaN) and the Eq. 3.35-3.36 weighted averages."""
    poles = diagram.poles
    sensors = diagram.recording.sensors
    rows = []
    for i, mode in enumerate(modes.itertuples(index=False)):
        for k, s in enumerate(sensors):
            nas = sorted(na for src, na in diagram.fits if src == s)
            own = poles[(poles.source == s) & (poles.rejected == "")]
            near = own[np.abs(own.freq_hz - mode.freq_hz) <= cluster_freq * mode.freq_hz]
            near = near.loc[near.groupby("na").energy.idxmax()] if len(near) else near
            relevant = [na for na in nas if na >= min(mode.na, nas[-1])] if nas else []
            shown = len(near) > 0 and len(near) >= 0.5 * len(relevant)
            own_const = np.nan + 0j
            if shown:
                at = near.iloc[int(np.argmin(np.abs(near.na.to_numpy() - mode.na)))]
                own_const = complex(at.vector[0])
            rows.append(
                {
                    "sensor": s,
                    "mode": i + 1,
                    "freq_hz": float(near.freq_hz.median()) if shown else np.nan,
                    "damping": float(near.damping.median()) if shown else np.nan,
                    "damped_freq_hz": float(near.damped_freq_hz.median()) if shown else np.nan,
                    "residue_mag": float(abs(shapes[k, i])),
                    "own_modal_constant": own_const,
                }
            )
    table = pd.DataFrame(rows)
    weighted = []
    for i, g in table.groupby("mode"):
        ok = g.dropna(subset=["freq_hz"])
        w = ok.residue_mag.to_numpy()
        weighted.append(
            {
                "mode": i,
                "freq_hz": float(np.sum(w * ok.freq_hz) / w.sum()) if len(ok) else np.nan,
                "damping": float(np.sum(w * ok.damping) / w.sum()) if len(ok) else np.nan,
                "sensors": len(ok),
            }
        )
    return table, pd.DataFrame(weighted)
