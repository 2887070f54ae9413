"""How many modes: the count's result and the tests it is built from.

:func:`armaxmodal.modes.count_search.count_modes` compares free refits of the maximum-likelihood modal model
(:func:`armaxmodal.estimate.dft_model.fit_modal_model`) with one mode fewer, one more, or one split, and keeps the
neighbour of lowest criterion while it lowers it. This module holds what it returns, :class:`ModeCount`, with the
verdicts derived from it, and the tests the search applies: the halves' agreement (``halves_chi2``), the pairing of
two pole sets and the residual's peak (the lines' effective share: :func:`armaxmodal.stats.effective_fraction`).
The criterion is Schwarz's BIC on the effective lines (the method page's "how many modes").

**Which world the record is in** (:class:`~armaxmodal.modes.mode_count.Adequacy`,
:func:`~armaxmodal.modes.mode_count.model_adequacy`). The criterion
and the halves' test assume the model is right. Where it is, they decide the number of modes
alone; where the model misfits far beyond the noise (a bridge moved at several supports by one
measured input, outputs that lead the input, a nonlinearity under a periodic input), the
likelihood buys ghost modes that soak up what the model lacks, and one stated rule says what a mode
shows beyond the criterion (:mod:`armaxmodal.modes.count_search`). The test compares the model's
residual with the noise the record holds by itself: the local polynomial method
(:func:`armaxmodal.spectra.local_polynomial_noise`) applied to the residual on the count's own
lines. Where the model is right the residual is the noise and each sensor's ratio of the two powers
is 1 (0.97-1.02 over bodies and light chains); what the model lacks that is smooth over a few lines
stays in it (1.3-35 on the bridge and shake-table records that misfit, 32-2,056 on the F-16).
Noise the input does not explain (another input, a cubic spring's distortion under a random input)
is noise to both, and leaves the ratio at 1.

The module holds the count's result and every test the search applies, and is longer than 400 lines
for it.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from armaxmodal.estimate.dft_model import DftLines, ModalModel, fit_modal_model
from armaxmodal.io.write import finite_or_none as finite  # strict JSON: None for NaN
from armaxmodal.modal import matched_poles, nearest_pole
from armaxmodal.modes.intervals import interval
from armaxmodal.modes.poles import beyond_band, borderline, reported
from armaxmodal.modes.settings import DEFAULTS, AgreementSettings, CountSettings, DftSettings
from armaxmodal.spectra import LPM_HALF_WIDTH, local_polynomial_noise
from armaxmodal.stats import Z95

__all__ = [
    "Adequacy",
    "Alternative",
    "FittedModel",
    "LeftOut",
    "ModeCount",
    "ModelTable",
    "StandIn",
    "Step",
    "Wanted",
    "halves_chi2",
    "model_adequacy",
    "split_start",
]

#: the count's thresholds when none are given (:class:`~armaxmodal.modes.settings.CountSettings`)
COUNT = DEFAULTS.count


#: the rule each world counts by, as the JSON and the notes name it
LIKELIHOOD_RULE = "criterion and halves"
COLUMN_RULE = "criterion, halves and a stable diagram column"


@dataclass(frozen=True)
class Adequacy:
    """The adequacy test's outcome.

    Attributes
    ----------
    ratio : (n_sensors,) ndarray
        Each sensor's residual power over the band divided by the noise power the local
        polynomial method measures in that residual (1 where the model explains the record).
    level : float
        The largest ratio of an adequate model (``CountSettings.adequacy_ratio``).

    See Also
    --------
    armaxmodal.modes.mode_count.model_adequacy : What makes one.

    Examples
    --------
    >>> import numpy as np
    >>> from armaxmodal.modes.mode_count import Adequacy
    >>> test = Adequacy(np.array([1.01, 3.2]), 1.25)
    >>> test.adequate, test.rule
    (False, 'criterion, halves and a stable diagram column')
    """

    ratio: np.ndarray
    level: float

    @property
    def adequate(self) -> bool:
        """Every sensor's ratio at most ``level``."""
        return bool(np.all(self.ratio <= self.level))

    @property
    def rule(self) -> str:
        """What a mode the count adds must show: the criterion and the halves' agreement where the
        model is adequate, and a stable column of the diagram besides where it is not."""
        return LIKELIHOOD_RULE if self.adequate else COLUMN_RULE

    def to_dict(self) -> dict:
        """The JSON form: ``ratio`` per sensor, ``level``, ``adequate`` and ``rule``.

        Returns
        -------
        dict
            Strict-JSON-ready (None for NaN).
        """
        return {
            "ratio": [finite(r) for r in self.ratio],
            "level": float(self.level),
            "adequate": self.adequate,
            "rule": self.rule,
        }


def model_adequacy(model: ModalModel, u: np.ndarray, level: float) -> Adequacy:
    """Test whether ``model`` explains its lines to their noise (see the module notes).

    Parameters
    ----------
    model : ModalModel
        A model fitted to DFT lines; its ``residual`` (n_lines, n_sensors) is tested.
    u : (n_lines,) complex ndarray
        The input's DFT on the same lines.
    level : float
        The largest ratio of an adequate model.

    Returns
    -------
    Adequacy
        Each sensor's ratio; NaN for all where the band holds fewer lines than the method's window
        (13), which is not shown adequate.

    See Also
    --------
    armaxmodal.modes.mode_count.Adequacy : What it returns.
    armaxmodal.spectra.local_polynomial_noise : The noise it compares the residual with.

    Examples
    --------
    >>> import armaxmodal as am
    >>> from armaxmodal.estimate.dft_model import DftLines, fit_modal_model
    >>> from armaxmodal.modes.mode_count import model_adequacy
    >>> from armaxmodal.modes.settings import DEFAULTS
    >>> exact = am.supine_human().modes()
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)
    >>> data = DftLines.from_recording(ride, (0.5, 28.0))
    >>> model = fit_modal_model(data, exact.freq_hz, exact.damping, "zoh", settings=DEFAULTS.dft)
    >>> model_adequacy(model, data.u, 1.25).adequate
    True
    """
    if np.size(u) < 2 * LPM_HALF_WIDTH + 1:  # too few lines to measure the noise: not shown adequate
        return Adequacy(np.full(model.residual.shape[1], np.nan), float(level))
    noise = local_polynomial_noise(u, model.residual).sum(axis=0)
    power = np.sum(np.abs(model.residual) ** 2, axis=0)
    return Adequacy(power / np.where(noise > 0, noise, np.nan), float(level))


@dataclass(frozen=True)
class Step:
    """One accepted step of the search: ``action`` ("remove", "add" or "split"), the mode's
    frequency (Hz; an addition's start), the criterion's fall (positive), and where an addition's
    new pole settled (Hz; NaN for a removal)."""

    action: str
    freq_hz: float
    bic_fall: float
    settled_hz: float = float("nan")


class FittedModel(NamedTuple):
    """One model the count fitted (a row of :meth:`ModeCount.models_table`), as statsmodels'
    ``ar_select_order`` keeps every candidate's criterion: the search's choices can be read off."""

    action: str  #: what the fit tried: "start", "remove", "add", "split", "converge", "leave out", "alternative"
    freq_hz: float  #: the mode it removed, added (its start) or split (Hz); NaN for the model as it stands
    n_modes: int  #: poles in the model
    neg2_loglik: float  #: ``-2 ln L`` on the effective lines
    n_params: int  #: the parameters that depend on the number of modes
    bic: float  #: the criterion on the effective lines (smaller is better)
    converged: bool  #: the fit met its tolerance (a screening fit stops at its cap)
    halves_agree: bool | None  #: its new poles the same in both halves (None: not asked)


class ModelTable:
    """The count's table as the search fills it: one :class:`FittedModel` per fit, in order, with ``-2 ln L`` and BIC
    on ``n_effective`` real numbers (:func:`armaxmodal.stats.effective_fraction`)."""

    def __init__(self, n_effective: float):
        self.n_eff, self.rows = n_effective, []
        self._live: dict[int, tuple[weakref.ref, int]] = {}  # a fitted model still alive: its row

    def add(self, action: str, freq_hz: float, model: ModalModel | None) -> ModalModel | None:
        """``model`` (None: nothing fitted, no row), with its row added."""
        if model is not None:
            self._live[id(model)] = (weakref.ref(model), len(self.rows))
            fit = float(model.neg2_loglik_on(self.n_eff)), model.n_params, float(model.bic(self.n_eff))
            self.rows.append(FittedModel(action, float(freq_hz), model.n_modes, *fit, model.converged, None))
        return model

    def halves(self, model: ModalModel, agree: bool | None) -> bool | None:
        """``agree`` (the halves' test of ``model``'s new poles), written into ``model``'s row."""
        ref, row = self._live.get(id(model), (lambda: None, -1))
        if ref() is model:
            self.rows[row] = self.rows[row]._replace(halves_agree=agree)
        return agree


class Alternative(NamedTuple):
    """A model the record cannot tell from the chosen one (:attr:`ModeCount.alternatives`)."""

    bic_difference: float  #: its criterion less the chosen model's
    model: ModalModel


class LeftOut(NamedTuple):
    """A start the search carried to where no mode is founded, left out (:attr:`ModeCount.carried_away`)."""

    start_hz: float  #: where the start was (Hz)
    went_hz: float  #: where the free fit took it (Hz)


class StandIn(NamedTuple):
    """A start carried to where no mode is founded that the model needs (:attr:`ModeCount.stand_ins`)."""

    start_hz: float  #: where the start was (Hz)
    went_hz: float  #: where the free fit took it (Hz)
    rise: float  #: the criterion's rise without it


class Wanted(NamedTuple):
    """One mode more the likelihood wants and the criterion refuses (:attr:`ModeCount.wanted`)."""

    freq_hz: float  #: where its new pole settled (Hz)
    ratio: float  #: likelihood ratio over the chosen model, on the effective lines
    dof: int  #: the parameters one mode adds
    rise: float  #: the criterion's rise with it (negative: a fall)
    in_diagram: bool  #: the diagram holds a stable column there to pick


@dataclass(frozen=True)
class ModeCount:
    """The modal model the nested tests chose, with the evidence.

    Attributes
    ----------
    model : ModalModel
        The chosen model.
    start : ModalModel
        The model of the starting set.
    steps : tuple of Step
        The accepted steps, in order.
    removal_rise : (n_modes,) ndarray
        Per chosen mode, how much the criterion rises when it is removed and the rest refitted
        free (large: the record needs it).
    best_addition : float
        The largest fall of the criterion any candidate addition or split gives (negative:
        every candidate makes the model worse).
    best_addition_hz : float
        Where that candidate's new pole settled (Hz; NaN when there was no candidate).
    effective_fraction : float
        The fraction of the lines that carry independent information (1 for white noise).
    trials : int
        Fits the search ran.
    unconfirmed_hz : tuple of float
        Additions the whole record accepted but one of its halves did not (Hz, the start).
    alternatives : tuple of Alternative
        The models with one mode fewer or more that the record cannot tell from the chosen one:
        each converged, with its criterion's difference from the chosen model's (under
        ``settings.decisive_bic``). The reported intervals cover their modes
        (``armaxmodal.modes.counted.counted_modes``).
    carried_away : tuple of LeftOut
        Starting modes the search carried to where no mode is founded, and which were left out
        of the chosen model. See ``_without_unfounded``.
    wanted : Wanted or ()
        The best addition BIC refuses decisively while its likelihood ratio is significant
        (beyond ``settings.decisive_alpha``) and its mode is the same in both halves, or else the best
        split of a reported mode that passes the same test (its criterion's change either way:
        the search splits only one mode). Empty: none.
    stand_ins : tuple of StandIn
        Starting modes the search carried to where no mode is founded but which the model needs
        (the criterion rises decisively without them): kept in the model, not reported, as
        out-of-band poles are.
    models : tuple of FittedModel
        Every model the count fitted, in the order fitted (:meth:`models_table`).
    band_hz : (float, float)
        The band of the lines the count decided on (Hz): which poles are modes of it.
    unsettled_hz : tuple of float
        Additions the criterion takes whose halves differ beyond the halves test's level
        ``agreement.alpha`` but not beyond ``settings.decisive_alpha``: taken, undecided (Hz, where
        the new pole settled).
    agreement : AgreementSettings
        The level of the halves' test.
    adequacy : Adequacy or None
        Whether the model the criterion and the halves chose explains the record to its noise
        (:func:`armaxmodal.modes.mode_count.model_adequacy`), and so the rule the count ran by. None: not tested.
    rule_refused : tuple
        ``(criterion's difference, its modes' Hz)``: the model the criterion and the halves chose
        where the record's model is not adequate and the stated rule refused it (its criterion less
        the chosen one's is minus the difference); empty where the two agree.

    See Also
    --------
    armaxmodal.modes.count_search.count_modes : What makes one.

    Examples
    --------
    >>> import armaxmodal as am
    >>> body, exact = am.supine_human(), am.supine_human().modes()  # exact: 5.83, 8.31, 13.50, 16.25 Hz
    >>> ride = am.simulate_recording(body, am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03, seed=2)
    >>> from armaxmodal.estimate.dft_model import DftLines
    >>> data = DftLines.from_recording(ride, (0.5, 28.0))
    >>> from armaxmodal.modes.count_search import count_modes
    >>> count = count_modes(data, exact.freq_hz, exact.damping, hold="zoh")
    >>> count.model.n_modes, count.verdicts(), round(count.effective_fraction, 1)
    (4, array(['needed', 'needed', 'needed', 'needed'], dtype=object), 1.0)
    """

    model: ModalModel
    start: ModalModel
    steps: tuple[Step, ...]
    removal_rise: np.ndarray
    best_addition: float
    best_addition_hz: float
    effective_fraction: float
    trials: int = field(default=0)
    unconfirmed_hz: tuple[float, ...] = ()
    alternatives: tuple[Alternative, ...] = ()
    carried_away: tuple[LeftOut, ...] = ()
    wanted: Wanted | tuple = ()
    stand_ins: tuple[StandIn, ...] = ()
    settings: CountSettings = COUNT
    dft: DftSettings = DEFAULTS.dft
    models: tuple[FittedModel, ...] = ()
    band_hz: tuple[float, float] = (0.0, float("inf"))
    unsettled_hz: tuple[float, ...] = ()
    agreement: AgreementSettings = DEFAULTS.agreement
    adequacy: Adequacy | None = None
    rule_refused: tuple = ()
    reach: float = DEFAULTS.cluster.freq

    def __post_init__(self):
        # the search hands its findings over as plain tuples; the result holds them by name
        for name, kind in (("alternatives", Alternative), ("carried_away", LeftOut), ("stand_ins", StandIn)):
            object.__setattr__(self, name, tuple(kind(*item) for item in getattr(self, name)))

    def models_table(self):
        """Every model the count fitted, one row each (``FittedModel``'s columns), in the order
        fitted: the removals, additions and splits tried at each step, their convergence, the halves'
        test, the equally good models.

        Returns
        -------
        DataFrame
            ``action``, ``freq_hz``, ``n_modes``, ``neg2_loglik``, ``n_params``, ``bic``,
            ``converged``, ``halves_agree``.
        """
        import pandas as pd

        return pd.DataFrame(list(self.models), columns=list(FittedModel._fields))

    def to_dict(self) -> dict:
        """The count's evidence for the JSON: the effective fraction of the lines, the fits run, the
        accepted steps, every model fitted (:meth:`models_table`) and every pole of the chosen model
        with its :meth:`verdicts`.

        Returns
        -------
        dict
            ``effective_fraction``, ``trials``, ``steps``, ``models``, ``adequacy``, ``rule_refused`` and ``poles``,
            strict-JSON-ready (None for NaN),
            as ``schemas/stabilise.schema.json``'s ``count`` describes.
        """

        return {
            "effective_fraction": finite(self.effective_fraction),
            "trials": int(self.trials),
            "steps": [
                {
                    "action": st.action,
                    "freq_hz": finite(st.freq_hz),
                    "bic_fall": finite(st.bic_fall),
                    "settled_hz": finite(st.settled_hz),
                }
                for st in self.steps
            ],
            "models": [
                {
                    **row._asdict(),
                    "freq_hz": finite(row.freq_hz),
                    "neg2_loglik": finite(row.neg2_loglik),
                    "bic": finite(row.bic),
                }
                for row in self.models
            ],
            "adequacy": None if self.adequacy is None else self.adequacy.to_dict(),
            "rule_refused": (
                {"bic_difference": finite(self.rule_refused[0]), "freq_hz": [finite(f) for f in self.rule_refused[1]]}
                if self.rule_refused
                else None
            ),
            "poles": [
                {"freq_hz": finite(f), "damping": finite(x), "removal_rise": finite(rise), "verdict": verdict}
                for f, x, rise, verdict in zip(
                    self.model.freq_hz, self.model.damping, self.removal_rise, self.verdicts(), strict=True
                )
            ],
        }

    def verdicts(self, band_hz=None) -> np.ndarray:
        """What the count makes of each pole of the chosen model, decided here and nowhere else:

        * ``"needed"``: a mode of the band whose removal (the rest refitted free) raises the
          criterion decisively (``settings.decisive_bic``);
        * ``"undecided"``: a mode of the band the record holds less firmly (the rise is smaller, or
          its halves differ beyond chance but not beyond ``settings.decisive_alpha``: ``unsettled_hz``):
          reported, and said tentative;
        * ``"stand_in"``: a start the search carried where no mode is founded but which the
          model needs (``stand_ins``, matched within ``reach``): kept in the
          model, not reported;
        * ``"not_a_mode"``: beyond the band, damped beyond ``MAX_DAMPING``, or a line (:func:`reported`);
        * ``"borderline"``: not one by its estimate, one by its 95 % interval (``poles.borderline``):
          not reported, and the record does not decide whether a mode of the band is there;
        * ``"beyond_band"``: a needed pole the record determines as a mode outside the band
          (``poles.beyond_band``): not reported, and named.

        Starts the search left out of the model (``carried_away``) are not among its poles.

        Parameters
        ----------
        band_hz : (float, float), optional
            The band (Hz); default ``band_hz``.

        Returns
        -------
        (n_modes,) ndarray of str
        """
        band = self.band_hz if band_hz is None else band_hz
        needed = self.removal_rise >= self.settings.decisive_bic
        verdict = np.where(needed, "needed", "undecided").astype(object)
        verdict[~reported(self.model, band)] = "not_a_mode"
        verdict[borderline(self.model, band)] = "borderline"
        verdict[needed & beyond_band(self.model, band)] = "beyond_band"
        for f in self.unsettled_hz:  # taken, though its halves differ beyond chance
            at = self._pole_at(f)
            if at is not None and verdict[at] == "needed":
                verdict[at] = "undecided"
        for stand_in in self.stand_ins:
            at = self._pole_at(stand_in.went_hz)
            if at is not None:
                verdict[at] = "stand_in"
        return verdict

    def _pole_at(self, f: float) -> int | None:
        """The model's pole nearest ``f`` (Hz) if within ``reach`` of it, else None:
        one pole, not every pole near (a close pair's other mode is a mode of its own)."""
        if not self.model.n_modes:
            return None
        at = nearest_pole(self.model.freq_hz, f)
        return at if abs(np.log(self.model.freq_hz[at] / f)) <= self.reach else None

    def reported(self, band_hz=None) -> np.ndarray:
        """Which of the model's poles are reported as modes of the band (bool per pole): those
        :meth:`verdicts` calls ``needed`` or ``undecided``.

        Parameters
        ----------
        band_hz : (float, float), optional
            The band (Hz); default ``band_hz``.

        Returns
        -------
        (n_modes,) bool ndarray
        """
        return np.isin(self.verdicts(band_hz), ("needed", "undecided"))

    def other_structures(self, i: int, same_row_freq: float) -> tuple[dict, bool]:
        """The reach of mode ``i``'s counterparts' 95 % intervals in the equally good models
        (``self.alternatives``): where the record cannot tell the number of modes, it cannot tell
        which model's values hold either, so the reported interval covers theirs
        (:mod:`armaxmodal.modes.intervals`). A counterpart is the alternative's pole paired with mode
        ``i`` one to one, within ``same_row_freq``; a mode the alternative lacks, or that moved
        farther (two merged into one), has none.

        Parameters
        ----------
        i : int
            The mode (the chosen model's pole).
        same_row_freq : float
            The relative frequency within which an alternative's pole is the mode's counterpart.

        Returns
        -------
        reach : dict
            ``{q}_other_lo/hi``: the counterparts' interval hull, NaN where there is none.
        widened : bool
            A counterpart's interval reaches beyond the mode's own.
        """
        m = self.model
        own = {
            "freq": list(interval("freq", m.freq_hz[i], Z95 * m.freq_sd[i])),
            "damping": list(interval("damping", m.damping[i], Z95 * m.damping_sd[i])),
        }
        reach = dict.fromkeys(("freq_other_lo", "freq_other_hi", "damping_other_lo", "damping_other_hi"), np.nan)
        widened = False
        for alt in (alternative.model for alternative in self.alternatives):
            for k, j in matched_poles(m.freq_hz, alt.freq_hz):
                if j != i or abs(np.log(alt.freq_hz[k] / m.freq_hz[i])) > same_row_freq:
                    continue
                for q, value, sd in (
                    ("freq", alt.freq_hz[k], alt.freq_sd[k]),
                    ("damping", alt.damping[k], alt.damping_sd[k]),
                ):
                    (lo, hi), ci = interval(q, value, Z95 * sd), own[q]
                    widened |= bool(lo < ci[0] or hi > ci[1])
                    ci[:] = [min(ci[0], lo), max(ci[1], hi)]
                    reach[f"{q}_other_lo"] = float(np.fmin(reach[f"{q}_other_lo"], lo))
                    reach[f"{q}_other_hi"] = float(np.fmax(reach[f"{q}_other_hi"], hi))
        return reach, widened


def halves_chi2(
    data: DftLines,
    model: ModalModel,
    halves,
    hold: str,
    max_nfev: int = COUNT.halves_nfev,
    dft: DftSettings = DEFAULTS.dft,
    fitter=fit_modal_model,
    agreement: AgreementSettings = DEFAULTS.agreement,
    reach: float = DEFAULTS.cluster.freq,
) -> np.ndarray:
    """Per pole of ``model``: how far apart the record's two halves (``halves``, lines weighted as
    ``data``; each fitted from ``model``'s poles by ``fitter``) put it: the squared differences of its
    frequency and damping in standard deviations of the difference, summed (each half's pole the one
    nearest the model's): a chi-square of 2 degrees of freedom where the halves agree. NaN where the
    sensors hardly move within ``reach`` of it in one half (``agreement.excitation_ratio``: a sweep
    passes it in one).

    Returns
    -------
    (n_modes,) ndarray
    """
    a, b = (
        fitter(h.weighted(data.weights), model.freq_hz, model.damping, hold, max_nfev, settings=dft) for h in halves
    )
    chi2 = np.zeros(model.n_modes)
    for i, f in enumerate(model.freq_hz):
        power = [h.response_power(f, reach) for h in halves]
        if min(power) < agreement.excitation_ratio * max(power):
            chi2[i] = np.nan
            continue
        j, k = nearest_pole(a.freq_hz, f), nearest_pole(b.freq_hz, f)
        for one, two, sd_one, sd_two in (
            (a.freq_hz, b.freq_hz, a.freq_sd, b.freq_sd),
            (a.damping, b.damping, a.damping_sd, b.damping_sd),
        ):
            chi2[i] += (abs(one[j] - two[k]) / max(np.hypot(sd_one[j], sd_two[k]), 1e-300)) ** 2
    return chi2


def residual_peak(model: ModalModel, data: DftLines, width_lines: int = COUNT.peak_width_lines) -> tuple[float, float]:
    """Where the model misses most: the line of the largest residual power (summed over
    sensors, smoothed over ``width_lines``), with a damping from its width; (Hz, ratio)."""
    power = np.sum(np.abs(model.residual) ** 2, axis=1)
    smooth = np.convolve(power, np.ones(width_lines) / width_lines, mode="same")
    k = int(np.argmax(smooth))
    f = float(np.abs(data.s[k]) / (2 * np.pi))
    above = smooth >= smooth[k] / 2
    lo, hi = k, k
    while lo > 0 and above[lo - 1]:
        lo -= 1
    while hi < smooth.size - 1 and above[hi + 1]:
        hi += 1
    width = float(np.abs(data.s[hi]) - np.abs(data.s[lo])) / (2 * np.pi)
    return f, float(np.clip(width / (2 * f), 0.01, 0.5))


def split_start(model: ModalModel, m: int) -> tuple[np.ndarray, np.ndarray]:
    """``model``'s poles with mode ``m`` split in two, a half-power bandwidth apart: (Hz, ratio)."""
    f, x = model.freq_hz[m], model.damping[m]
    half = max(x, 0.01) / 2
    return (
        np.r_[np.delete(model.freq_hz, m), f * (1 - half), f * (1 + half)],
        np.r_[np.delete(model.damping, m), x / 2, x / 2],
    )
