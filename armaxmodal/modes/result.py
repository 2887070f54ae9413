"""The result of ``select_modes``: ``ModeSelection``, its JSON contract
(``schemas/stabilise.schema.json``) and its verdict, and each sensor's own view of the selected
modes (thesis Section 3.3.4):

* ``per_sensor_table`` -- Table 3.2: each sensor's own frequency and damping of every
  selected mode (gaps where the sensor does not show it) and the Eq. 3.35-3.36
  residue-weighted averages.
* ``supplement_shapes`` -- a sensor whose own model does not show a mode leaves a gap in
  that mode's shape (the 'X' of Table 3.2). Eq. (3.34) fills it from the measured
  transmissibility at the damped natural frequency, ``phi_p = T_pl s_ql phi_l`` with the
  scale ``s_ql = |phi_q / phi_l| / |T_ql|`` taken from a known neighbour to reduce the
  influence of neighbouring modes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from armaxmodal.estimate.dft_model import ModalModel
from armaxmodal.io.write import finite_or_none
from armaxmodal.modal import mode_record
from armaxmodal.modes.diagram import StabilisationDiagram
from armaxmodal.modes.modal_check import ModalCheck
from armaxmodal.modes.mode_count import ModeCount
from armaxmodal.modes.settings import DEFAULTS, SelectionSettings
from armaxmodal.prepare.preparation import Preparation
from armaxmodal.quality_warnings import UNCERTAIN_CODES, QualityWarning
from armaxmodal.recording import Recording

__all__ = ["ModeSelection", "per_sensor_table", "record_header", "supplement_shapes", "transmissibility_at", "verdict"]


@dataclass(frozen=True)
class ModeSelection:
    """Physical modes picked from a stabilisation diagram.

    Attributes
    ----------
    modes : DataFrame
        One row per mode, by frequency: freq_hz, damping, damped_freq_hz and 95 % intervals
        (``*_ci95_lo/hi``), the parts the intervals combine (the estimate's ``freq_sd`` and
        ``damping_sd``, the other structures' ``*_other_lo/hi``, the segments'
        ``*_segment_half``: :mod:`armaxmodal.modes.intervals`), na of the representative fit,
        count and support of the cluster, its spread (standard deviation over orders) and medoid.
    shapes : (n_sensors, n_modes) complex ndarray
        EPFRF modal constants per sensor (Eq. 3.24) from the representative fit.
    per_sensor : DataFrame
        Table 3.2 form: one row per sensor and mode with the sensor's own frequency, damping
        and residue magnitude, NaN where the sensor does not show the mode (the thesis's X).
    weighted : DataFrame
        Eqs. 3.35-3.36: per mode, the mean of the per-sensor values weighted by ``|M_ij|``.
    diagram : StabilisationDiagram
    refinement : ModalModel or None
        The frequency-domain refit (:func:`armaxmodal.modes.state.refine_modes`); its ``hold`` is the
        inter-sample behaviour the data chose. ``modes.estimator`` says which values are
        reported: the refit for a band-limited recording, the ARMAX fit (the exact model
        class) for a held input.
    own_warnings : tuple of QualityWarning
        The selection's own notes (``warnings`` adds the diagram's).
    check : ModalCheck or None
        The modal-model check of the modes.
    count : ModeCount or None
        The maximum-likelihood count, when it ran.
    settings : SelectionSettings
        The thresholds that made this selection (:mod:`armaxmodal.modes.settings`).
    picks : list of float or None
        The frequencies (Hz) the modes were picked at by hand, sorted; None for an automatic selection.
    counted : bool
        The modes are the count's (``modes`` holds its columns: ``count_undecided``, ``structure_widened``,
        ``estimator_widened``); False where no count ran or it kept no mode of the band.
    segments : int
        The disjoint segments of the segment spread (``modes`` holds its columns where at least 2).

    See Also
    --------
    armaxmodal.select_modes : What makes one.
    armaxmodal.modes.settings.SelectionSettings : The thresholds it carries.

    Examples
    --------
    >>> import armaxmodal as am
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)
    >>> selection = am.select_modes(am.stabilisation_diagram(ride, range(4, 13, 2), per_sensor=False), segments=0)
    >>> selection.quality
    'good'
    >>> selection.modes.freq_hz.round(1).tolist()  # exact: 5.83, 8.31, 13.50, 16.25 Hz
    [5.8, 8.3, 13.6, 16.2]
    """

    modes: pd.DataFrame
    shapes: np.ndarray
    per_sensor: pd.DataFrame
    weighted: pd.DataFrame
    diagram: StabilisationDiagram
    refinement: ModalModel | None = None
    own_warnings: tuple[QualityWarning, ...] = ()
    check: ModalCheck | None = None
    count: ModeCount | None = None
    settings: SelectionSettings = field(default=DEFAULTS, repr=False)
    picks: list[float] | None = None
    counted: bool = False
    segments: int = 0

    @property
    def reconstruction_error(self) -> float:
        """The modal-model check's relative misfit (:mod:`armaxmodal.modes.modal_check`): the
        largest output's relative RMS difference between the measured H1 and its LSFD fit
        by the selected poles with residual terms and a delay. Computed once, in
        :func:`~armaxmodal.select_modes`: the CLI, the figure and the JSON report the same number."""
        return self.check.overall_error if self.check is not None else float("nan")

    @property
    def quality(self) -> str:
        """``"poor"`` when the modal-model check fails; ``"uncertain"`` when it passes but a
        warning of ``armaxmodal.quality_warnings.UNCERTAIN_CODES`` stands (the record does not decide
        the number of modes, two modes are closer than it separates, or the preparation found a
        fault that moves modes); else ``"good"``."""
        if self.check is None or not self.check.passed:
            return "poor"
        return "uncertain" if self.uncertain_because else "good"

    @property
    def verdict(self) -> str:
        """The closing line of ``stabilise``: the quality and why (:func:`verdict`)."""
        return verdict(self.check, len(self.modes), self.uncertain_because)

    def _repr_html_(self) -> str:
        """A notebook's view: the verdict and the modes with their intervals."""
        import html

        from armaxmodal.io.report.selection_report import modes_table

        table = modes_table(self).to_html(index=False, float_format=lambda v: f"{v:.4g}", border=0)
        return f"<p><b>{html.escape(self.verdict)}</b></p>{table}"

    @property
    def uncertain_because(self) -> list[str]:
        """The codes of the warnings that make a passing selection uncertain, sorted."""
        return sorted({w.code for w in self.warnings if w.code in UNCERTAIN_CODES})

    @property
    def warnings(self) -> list[QualityWarning]:
        """The diagram's data-quality warnings and the selection's own."""
        return self.diagram.warnings + list(self.own_warnings)

    def to_dict(self, shapes: str = "shared") -> dict:
        """The JSON contract of the ``stabilise`` command.

        ``shapes="shared"`` reports the shared-pole residues (complete by construction);
        ``"per_sensor"`` each sensor's own residue, with gaps filled by Eq. (3.34) and
        flagged ``supplemented``.

        Parameters
        ----------
        shapes : {"shared", "per_sensor"}
            Which residues give the mode shapes.

        Returns
        -------
        dict
            Strict-JSON-ready (no NaN), as ``schemas/stabilise.schema.json`` describes.
        """
        if shapes not in ("shared", "per_sensor"):
            raise ValueError(f"shapes: expected 'shared' or 'per_sensor', got {shapes!r}.")
        rec = self.diagram.recording
        if shapes == "shared":
            matrix, flags = self.shapes, np.zeros(self.shapes.shape, dtype=bool)
        else:
            matrix, flags = supplement_shapes(self)
        modes = []
        for i, row in enumerate(self.modes.itertuples(index=False)):
            record = mode_record(row, matrix[:, i], rec.sensors, flags[:, i])
            record.update(
                orders_supporting=int(row.count),
                freq_spread_hz=float(row.freq_spread),
                damping_spread=float(row.damping_spread),
            )
            if self.segments >= 2:
                record["segment_spread"] = {
                    "segments_found": int(row.segments_found),
                    "freq_sd_hz": finite_or_none(row.freq_segment_sd),
                    "damping_sd": finite_or_none(row.damping_segment_sd),
                }
                record["model_error_dominates"] = bool(row.model_error_dominates)
            record["picked"] = self.picks is not None and bool(np.isfinite(row.picked_hz))
            if self.counted:  # the modal model's count (modes/counted.py), the two estimators (modes/intervals.py)
                record["count_undecided"] = bool(row.count_undecided)
                record["interval_covers_other_counts"] = bool(row.structure_widened)
                record["interval_covers_other_estimator"] = bool(row.estimator_widened)
            modes.append(record)
        per_sensor = [
            {k: (None if isinstance(v, float) and np.isnan(v) else v) for k, v in r.items()}
            for r in self.per_sensor.drop(columns=["own_modal_constant"]).to_dict("records")
        ]
        t = self.diagram.tolerances
        prep = self.diagram.preparation
        return {
            **record_header(rec, prep, self.warnings),
            "nk": self.diagram.orders[0].nk,
            "orders_na": [o.na for o in self.diagram.orders],
            "tolerances": {"freq": t.freq, "damping": t.damping, "shape": t.shape},
            "quality": self.quality,
            "reconstruction_error": finite_or_none(self.reconstruction_error),
            "modal_check": None if self.check is None else self.check.to_dict(),
            "intersample_hold": None if self.refinement is None else self.refinement.hold,
            "estimator": sorted(set(self.modes.estimator)),
            "picks": self.picks,
            "settings": self.settings.to_dict(),
            "count": None if self.count is None else self.count.to_dict(),
            "modes": modes,
            "per_sensor": per_sensor,
        }


def filled_samples_scale(recording, preparation) -> tuple[float, list[QualityWarning]]:
    """The factor every interval is widened by for samples the reader filled in (``gap_filled``,
    ``dropped_packet``): an interpolated sample carries no information, so a record of ``N``
    samples with ``k`` filled holds ``N - k`` observations, and a standard deviation the fit
    computed from ``N`` is too small by ``sqrt(N / (N - k))``. Counted in the record's own
    samples, before any resampling. Returns ``(factor, notes)``; 1 and none without filled samples."""
    filled = sum(
        w.value or 0.0 for w in recording.meta.get("read_warnings", ()) if w.code in ("gap_filled", "dropped_packet")
    )
    if not filled:
        return 1.0, []
    # gap_filled counts one channel's samples; a filled sample of any channel is lost to the fit
    n = recording.duration * (recording.fs if preparation is None else preparation.original_fs)
    factor = float(np.sqrt(n / max(n - filled, 1.0)))
    note = QualityWarning(
        "gap_filled",
        (),
        f"{filled:g} filled sample(s) carry no information: every interval is widened by {factor:.6f} "
        f"(sqrt(N / (N - filled)), N = {n:.0f})",
        factor,
    )
    return factor, [note]


def verdict(check, n_modes: int, uncertain_because: list[str] = ()) -> str:
    """The closing line: whether the modes explain the record, and whether the record decides them
    (``uncertain_because``: the codes of the warnings that leave it undecided)."""
    if n_modes == 0:
        return "quality: POOR -- no stable mode found: the no_modes note says why each cluster was rejected"
    if check is not None and check.passed and uncertain_because:
        return (
            f"quality: UNCERTAIN -- the {n_modes} selected mode(s) explain the measured FRF, but the record does not "
            f"settle them: {', '.join(uncertain_because)} (see the notes)"
        )
    if check is not None and check.passed:
        return f"quality: good -- the {n_modes} selected mode(s) explain the measured FRF of every checked output"
    if check is not None and check.unconfirmed_hz and not check.failing:
        where = ", ".join(f"{f:.2f}" for f in check.unconfirmed_hz)
        return f"quality: POOR -- the record does not confirm the mode(s) at {where} Hz (no coherent H1 there)"
    if check is None or not check.failing:
        return "quality: POOR -- no output has coherent lines to check the modes against: treat them as unconfirmed"
    worst = float(np.nanmax(check.model_error))
    return (
        f"quality: POOR -- the selected modes do not explain the measured FRF of {', '.join(check.failing)} "
        f"(model error up to {100 * worst:.0f} %): treat them as unconfirmed (see the warning)"
    )


#: the columns of an empty selection (what the command line and the JSON read of a mode)
_MODE_COLUMNS = (
    "freq_hz",
    "damping",
    "damped_freq_hz",
    "freq_ci95_lo",
    "freq_ci95_hi",
    "damping_ci95_lo",
    "damping_ci95_hi",
    "na",
    "count",
    "support",
    "freq_spread",
    "damping_spread",
    "estimator",
)


def no_mode_selection(diagram: StabilisationDiagram, why: str, settings: SelectionSettings = DEFAULTS) -> ModeSelection:
    """The selection of a diagram with no stable mode: no modes, quality ``poor``, and a
    ``no_modes`` note that says why every cluster was rejected and what to do."""
    note = QualityWarning(
        "no_modes", (), f"{why}. Widen the band, extend the order range, or check that the input excites the structure."
    )
    empty = pd.DataFrame(columns=list(_MODE_COLUMNS))
    per_sensor = pd.DataFrame(columns=["sensor", "mode", "own_modal_constant"])
    shapes = np.zeros((len(diagram.recording.sensors), 0), dtype=complex)
    return ModeSelection(
        empty, shapes, per_sensor, pd.DataFrame(columns=["mode"]), diagram, None, (note,), None, settings=settings
    )


def record_header(recording: Recording, preparation: Preparation | None, warnings) -> dict:
    """The opening keys of every result's JSON: the rates, what the preparation did, the
    warnings, and the channels.

    Returns
    -------
    dict
        ``armaxmodal_version``, ``fs`` (as recorded), ``analysis_fs``, ``preprocessing``, ``warnings``,
        ``input``, ``outputs``.
    """
    from armaxmodal._version import __version__

    return {
        "armaxmodal_version": __version__,  # the release the notes (docs: release notes) describe
        "fs": recording.fs if preparation is None else preparation.original_fs,
        "analysis_fs": recording.fs,
        "preprocessing": None if preparation is None else preparation.to_dict(),
        "warnings": [w.to_dict() for w in warnings],
        "input": recording.input_name,
        "outputs": list(recording.sensors),
    }


def per_sensor_table(diagram, modes, shapes, cluster_freq):
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


def transmissibility_at(recording, freq_hz: float) -> np.ndarray:
    """Measured H1 of every sensor over the base input at one frequency (linear interpolation).

    Uses four averages only, for a fine frequency grid: a lightly damped resonance is
    narrower than the default plotting resolution, and Eq. (3.33) is read right at it.
    """
    from armaxmodal.spectra import measured_frf

    f, h, _ = measured_frf(recording, nperseg=max(recording.n_samples // 4, 16))
    return np.array(
        [np.interp(freq_hz, f, h[:, k].real) + 1j * np.interp(freq_hz, f, h[:, k].imag) for k in range(h.shape[1])]
    )


def supplement_shapes(selection) -> tuple[np.ndarray, np.ndarray]:
    """Per-sensor mode shapes with the gaps filled by Eq. (3.34).

    Parameters
    ----------
    selection : ModeSelection

    Returns
    -------
    shapes : (n_sensors, n_modes) complex ndarray
        Each sensor's own modal constant where it shows the mode, Eq. (3.34) elsewhere.
    supplemented : (n_sensors, n_modes) bool ndarray
        True where a component was filled from the transmissibility.
    """
    table = selection.per_sensor
    sensors = list(selection.diagram.recording.sensors)
    n_modes = len(selection.modes)
    shapes = np.full((len(sensors), n_modes), np.nan + 0j)
    for row in table.itertuples(index=False):
        shapes[sensors.index(row.sensor), row.mode - 1] = row.own_modal_constant
    supplemented = np.zeros(shapes.shape, dtype=bool)
    for r, mode in enumerate(selection.modes.itertuples(index=False)):
        known = np.flatnonzero(~np.isnan(shapes[:, r]))
        missing = np.flatnonzero(np.isnan(shapes[:, r]))
        if missing.size == 0:
            continue
        if known.size == 0:
            # no sensor shows it on its own: fall back on the shared-pole shape, all flagged
            shapes[:, r] = selection.shapes[:, r]
            supplemented[:, r] = True
            continue
        t = transmissibility_at(selection.diagram.recording, mode.damped_freq_hz)
        order = known[np.argsort(-np.abs(shapes[known, r]))]
        ell = order[0]  # reference: the largest known component
        scale = 1.0
        if order.size > 1:
            q = order[1]  # a known neighbour fixes the scale (s_ql)
            scale = abs(shapes[q, r] / shapes[ell, r]) / abs(t[q] / t[ell])
        for p in missing:
            shapes[p, r] = (t[p] / t[ell]) * scale * shapes[ell, r]
            supplemented[p, r] = True
    return shapes, supplemented
