"""The thresholds of the mode selection, in one place: one frozen settings object per stage of
``select_modes`` (:mod:`armaxmodal.modes.pipeline`), each value with the measurement behind it.

``select_modes(settings=SelectionSettings(count=CountSettings(decisive_bic=6.0)))`` overrides any
of them; the result carries the settings that made it (``ModeSelection.settings``, and
``"settings"`` in the JSON). Values that answer the same question are derived from one another,
never copied: a pick's reach and a counted mode's row reach are the clustering's frequency reach,
two modes told apart by shape use the merge's MAC, what a line is stands in ``LineSettings``, and
whether the record agrees with itself is asked at one level (``AgreementSettings``).
"""

from __future__ import annotations

import math
from dataclasses import MISSING, asdict, dataclass, field, fields

from armaxmodal.exceptions import SettingsError

__all__ = [
    "AgreementSettings",
    "ClusterSettings",
    "CountSettings",
    "DftSettings",
    "FrfSettings",
    "LineSettings",
    "NoteSettings",
    "Resolution",
    "SelectionSettings",
    "SweepSettings",
]


class _Settings:
    """Settings print the fields that differ from their defaults: a signature's default reads
    ``CountSettings()``, not every threshold's value, and a tuned object names what was tuned."""

    def __repr__(self) -> str:
        def default(f):
            return f.default_factory() if f.default is MISSING else f.default  # type: ignore[misc]

        changed = [f"{f.name}={getattr(self, f.name)!r}" for f in fields(self) if getattr(self, f.name) != default(f)]
        return f"{type(self).__name__}({', '.join(changed)})"


@dataclass(frozen=True)
class Resolution:
    """How finely an H1 must resolve the narrowest mode: ``lines_per_bandwidth`` Welch lines in its
    half-power bandwidth ``2 xi f``, from at least ``min_segments`` half-overlapping segments."""

    lines_per_bandwidth: int
    min_segments: int


#: the FRF peak search: a peak must stand out over 4 lines either side (a noise bump is a line
#: or two wide), so the narrowest mode spans 4 lines; 4 segments at least
PEAK_RESOLUTION = Resolution(lines_per_bandwidth=4, min_segments=4)
#: the modal-model check: 2 lines per bandwidth (the H1's bias at a peak is about -(line / bandwidth)^2 / 3 with a Hann
#: window: -8 % at two lines) from 8 segments at least (with fewer, the coherence of an unrelated line reaches 0.8 by
#: chance: its estimate is biased by about 1 / segments)
CHECK_RESOLUTION = Resolution(lines_per_bandwidth=2, min_segments=8)
#: the record's parts the spread is measured over, when not given (``select_modes(segments=...)``)
N_SEGMENTS = 3


#: the thresholds that are a probability, a share or a MAC: at most 1
_AT_MOST_ONE = frozenset(
    {
        "min_support",
        "merge_mac",
        "decisive_alpha",
        "alpha",
        "oversampled_fraction",
        "min_damping",
        "max_damping",
        "excitation_ratio",
    }
)


def _checked(settings) -> None:
    """Refuse a value no threshold can take, naming it and its default: every threshold here is a
    positive finite number (a whole one for counts), and a probability, share or MAC is at most 1."""
    name = type(settings).__name__
    for f in fields(settings):
        value, default = getattr(settings, f.name), f.default if f.default is not MISSING else None
        whole = isinstance(default, int) and not isinstance(default, bool)
        if isinstance(value, bool) or not isinstance(value, int if whole else (int, float)):
            kind = "whole number" if whole else "number"
            raise SettingsError(f"{name}.{f.name}: expected a {kind}, got {value!r} (the default is {default!r}).")
        if not (math.isfinite(value) and value > 0):
            raise SettingsError(
                f"{name}.{f.name}: expected a positive number, got {value!r} (the default is {default!r})."
            )
        if f.name in _AT_MOST_ONE and value > 1:
            raise SettingsError(
                f"{name}.{f.name}: a probability, share or MAC is at most 1, got {value!r} (the "
                f"default is {default!r})."
            )


@dataclass(frozen=True, repr=False)
class ClusterSettings(_Settings):
    """Which poles of the diagram are one mode (stages ``candidates`` and ``merge``)."""

    #: relative frequency distance within which a pole joins a cluster (its median); also a pick's
    #: reach, a counted mode's row reach (:attr:`pick_reach`, :attr:`same_row_freq`), how far a
    #: finished fit's pole may lie from the pole it finishes (farther, it is another pole), and
    #: where another fit's pole is the mode's: a segment's, a half's, a count's addition or moved
    #: start (AgreementSettings.match_freq, 5 %, and the count's 3 % until 2026-12-07)
    freq: float = 0.05
    #: relative damping distance within which a pole joins a cluster
    damping: float = 0.5
    #: share of the swept orders a cluster must hold poles of to be a mode of the diagram
    min_support: float = 0.4
    #: shape agreement (MAC) above which two close modes are one mode split by over-modelling;
    #: also the agreement at which two counted modes are not told apart by shape
    merge_mac: float = 0.8
    #: a pole is stable across the diagram when poles of at least this many orders lie near it:
    #: a left-out cluster is a candidate for the count, a cluster at an unexplained H1 peak is
    #: proposed to it, and a pick takes a cluster, only then
    min_orders: int = 3

    @property
    def pick_reach(self) -> float:
        """A pick takes a cluster whose median lies within this relative distance: the clustering's
        own reach, so a pick never takes a column the diagram shows as another mode's."""
        return self.freq

    @property
    def same_row_freq(self) -> float:
        """A counted mode within this relative frequency of a selected one keeps that row's cluster
        facts (orders, support, spread): the clustering's own reach."""
        return self.freq

    def __post_init__(self):
        _checked(self)


@dataclass(frozen=True, repr=False)
class LineSettings(_Settings):
    """Is a pole of the diagram a line (a periodic disturbance) or a mode, in one place for its
    ``periodic_disturbance`` note and the diagnosis."""

    #: damping below this, at a pole the input does not drive, is a line, not a structural mode: a
    #: hum on a fixture copy's output gave 5e-5-3e-4 at every order, a line on the input alone up to
    #: 1.7e-3; the lightest mode of the measured records is 4.8e-3 (the F-16's torsion). The damping
    #: alone does not decide: a two-mass chain damped 0.05 % and 0.1 % is driven, and its modes are modes
    undamped: float = 2e-3
    #: poles of one line across orders agree to this relative frequency (the hum: 3e-4)
    freq_tol: float = 1e-3
    #: the input carries the line too when its PSD there stands this far above the median of the
    #: neighbouring lines (10 dB; a Welch average of seven segments exceeds it by chance with
    #: probability ~1e-9)
    input_ratio: float = 10.0

    def __post_init__(self):
        _checked(self)


@dataclass(frozen=True, repr=False)
class FrfSettings(_Settings):
    """What the measured H1 says (stages ``propose_by_frf``, ``screen_by_frf`` and ``check``): the
    LSFD check and its support test (whose F-test runs at ``AgreementSettings.alpha``)."""

    #: a mode is kept when leaving it out raises the misfit of some output by at least this
    #: fraction (the relative RMS; 10 % in the residual sum of squares) and the rise is
    #: significant (at ``AgreementSettings.alpha``, the selection's one false-alarm rate).
    #: Measured with the product's own selections: the spurious poles and halves of split peaks
    #: on the measured records (stiff 1-storey 42.9 Hz, stiff 3-storey 9.0 Hz beside 8.0, flex
    #: 3-storey 36.8 and 38.0 Hz, a bridge's 6.6 Hz) raise it by 0.5-4 %; the weakest real modes
    #: (the F-16's 3.96 and 6.61 Hz at level 1) by 6-7 %, and the others by 12 % to several times.
    model_error_rise: float = 0.05
    #: delays searched, samples either way, in steps of :attr:`delay_step_samples`: channels
    #: are aligned by whole samples before the fit, so what is left is a few samples at most
    max_delay_samples: float = 4.0
    delay_step_samples: float = 0.25
    #: the largest model error (the misfit beyond the H1's random error) of an output whose
    #: modes explain it. Measured on records whose modes are right and complete (synced
    #: shake-table runs, F-16 multisine levels 1-7, the bridge records, the fixtures; the
    #: validation page's table): 0.01-0.43, the highest on stiff3 Northridge, whose peaks the
    #: ARMAX fit carries as doublets. The same records with their strongest mode left out read
    #: 0.50-0.96 on the output that shows it. The limit sits between the two.
    model_error_limit: float = 0.5
    #: what the H1 shows spans this many lines: a mode is confirmed by a coherent line within its
    #: half-power half-width and this many lines, and a misfit band is named where the misfit of
    #: a line exceeds half the H1 there and three times its random error over at least this many
    #: neighbouring lines (3 for the bands until 2026-12-07: no real record's note changed at 4)
    feature_lines: int = 4

    def __post_init__(self):
        _checked(self)


@dataclass(frozen=True, repr=False)
class DftSettings(_Settings):
    """The variable-projection fits of the modal model to the record's DFT (stages ``refit`` and
    ``count``)."""

    #: the lowest and highest damping ratio a free pole may take: a pole within twice the lowest is
    #: a line (a periodic disturbance, not a mode of the structure: ``poles.at_fit_floor``); above
    #: the highest, no resonance is left to fit
    min_damping: float = 1e-4
    max_damping: float = 0.95
    #: relative change of the cost and of the parameters at which a fit stops: a relative change
    #: of 1e-6 in the residual moves ``-2 ln L`` by about 0.03 at the 33,000 real numbers of a
    #: 120 s ride of five sensors, far below the criterion's decisive 10, and the parameters by
    #: a thousandth of their standard error (0.1-2 % of a frequency)
    fit_tol: float = 1e-6

    def __post_init__(self):
        _checked(self)
        if self.min_damping >= self.max_damping:
            raise SettingsError(
                f"DftSettings: min_damping ({self.min_damping!r}) must lie below max_damping ({self.max_damping!r})."
            )


@dataclass(frozen=True, repr=False)
class NoteSettings(_Settings):
    """Thresholds of the informative notes (stage ``finish``)."""

    #: every mode found below this share of the Nyquist frequency: the record is oversampled
    #: for its structure (the measured records here: 28-66 %; the supine ride at 1 kHz: 3 %)
    oversampled_fraction: float = 0.1
    #: ... and the band suggested ends at this multiple of the highest mode found
    suggested_band_factor: float = 2.5

    def __post_init__(self):
        _checked(self)


@dataclass(frozen=True, repr=False)
class CountSettings(_Settings):
    """The count by nested tests of the maximum-likelihood modal model (stage ``count``): the
    only stage that keeps or drops a mode."""

    #: a change of the criterion this large is "very strong" evidence (Kass & Raftery 1995): a
    #: mode's removal, or a candidate's addition, that moves it less leaves the count undecided
    decisive_bic: float = 10.0
    #: a probability this small is beyond chance among the handful of trials a count makes (the
    #: probability-scale twin of :attr:`decisive_bic`). A refused addition whose likelihood ratio a
    #: chi-square of its parameters puts beyond it leaves the count undecided (when its mode is the
    #: same in both halves): BIC's penalty grows with the data, so a weakly seen mode can raise the
    #: likelihood far beyond chance and still lose on BIC; 1e-6 keeps the largest of a handful of
    #: candidates at chance (the battery's 46 bodies: at most the 1e-3 quantile) far below it.
    #: Where the model is adequate, a new pole the halves refuse at ``agreement.alpha`` but not at
    #: this level is taken, tentative (a weak mode's damping 3.6 standard deviations apart in its
    #: halves; 1e-6: one value 5.3 apart); where it misfits, its standard deviations are no judge
    #: and ``agreement.alpha`` refuses
    decisive_alpha: float = 1e-6
    #: search steps at most (each accepted step changes the count by one)
    max_steps: int = 6
    #: residual evaluations of a screening fit: the candidates are compared after this many steps
    #: from their starts, and the best of each kind is then iterated to convergence
    screen_nfev: int = 10
    #: residual evaluations of the chosen model's last fit, to convergence
    final_nfev: int = 200
    #: residual evaluations of each half's fit in the halves test
    halves_nfev: int = 40
    #: the nested tests run on at most this many samples of a record (18 min at 60 Hz, 9 at 120 Hz:
    #: every body's modes are counted on less); a longer record's chosen model is fitted whole
    max_samples: int = 65_536
    #: left-out clusters of the diagram tried as additions: the largest few (each costs a fit)
    max_candidates: int = 3
    #: lines either side of the residual's peak averaged to place a new pole
    peak_width_lines: int = 9
    #: the counted model is adequate where no sensor's residual power exceeds this multiple of the
    #: noise the local polynomial method measures in it (:func:`armaxmodal.modes.mode_count.model_adequacy`): 0.97-1.02
    #: on 11 simulated bodies and light chains; 1.3-35 on the bridge and shake-table records that misfit
    #: (Painter Street's 2021 event 9-35), 32-2,056 on the F-16's four levels; 0.79-1.22 on the others
    adequacy_ratio: float = 1.25

    def __post_init__(self):
        _checked(self)


@dataclass(frozen=True, repr=False)
class AgreementSettings(_Settings):
    """Does the record agree with itself, asked three ways: its two halves (a count's new pole, a mode
    the H1 cannot confirm), its disjoint segments (each mode's spread) and its two estimators. One
    multiplicity policy for the three: each test is one family, its false-alarm rate over every value
    it judges ``alpha``; values judged together pool into one chi-square of their standardised
    differences (the halves: a trial's new poles' frequency and damping; the estimators: every
    mode's), values judged one by one share ``alpha`` (Bonferroni: the segments' modes)."""

    #: each test's false-alarm rate (the estimators' test: 30-59 on the F-16's levels for 12 values, 77
    #: for 6 on a ride with a cubic spring, none on its linear twin; the 1 % points are 26.2 and 16.8),
    #: and the level of the modal-model check's support F-test (``FrfSettings.model_error_rise``)
    alpha: float = 0.01
    #: the halves test a pole where the poorer holds this share of the other's response power within the
    #: clustering's reach
    #: of it (sweeps 3e-5-1e-2 on the F-16 and a ride; at the modes, earthquakes, random 0.021-1, a 2 Hz sine 3e-3-0.4)
    excitation_ratio: float = 0.01

    def __post_init__(self):
        _checked(self)


@dataclass(frozen=True, repr=False)
class SelectionSettings(_Settings):
    """Every threshold of :func:`armaxmodal.select_modes`, one object per stage.

    Attributes
    ----------
    cluster : ClusterSettings
        Which poles are one mode (``candidates``, ``merge``, picks, the count's candidates).
    lines : LineSettings
        Which poles of the diagram are lines: its ``periodic_disturbance`` note and the
        diagnosis read the defaults (the diagram is made before any selection). The count's
        lines are the modal model's poles at its fit's damping floor
        (``armaxmodal.modes.poles.at_fit_floor``).
    frf : FrfSettings
        The modal-model check of the measured H1, and what it proposes and screens.
    dft : DftSettings
        The modal model's fits to the record's DFT.
    count : CountSettings
        The count by nested tests, and the separation of close modes.
    agreement : AgreementSettings
        The one level of the halves', the segments' and the two estimators' tests.
    notes : NoteSettings
        The informative notes' thresholds.

    See Also
    --------
    armaxmodal.select_modes : Takes them as ``settings``.
    armaxmodal.modes.settings.SweepSettings : The sweep's own numbers.

    Examples
    --------
    >>> from armaxmodal.modes.settings import CountSettings, SelectionSettings
    >>> strict = SelectionSettings(count=CountSettings(decisive_bic=20.0))
    >>> strict.count.decisive_bic, SelectionSettings().count.decisive_bic
    (20.0, 10.0)
    >>> strict.cluster.pick_reach  # derived from the clustering's reach, never copied
    0.05
    """

    cluster: ClusterSettings = field(default_factory=ClusterSettings)
    lines: LineSettings = field(default_factory=LineSettings)
    frf: FrfSettings = field(default_factory=FrfSettings)
    dft: DftSettings = field(default_factory=DftSettings)
    count: CountSettings = field(default_factory=CountSettings)
    agreement: AgreementSettings = field(default_factory=AgreementSettings)
    notes: NoteSettings = field(default_factory=NoteSettings)

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            expected = f.default_factory  # type: ignore[misc]
            if not isinstance(value, expected):
                raise TypeError(f"settings.{f.name}: expected a {expected.__name__}, got {type(value).__name__}.")

    def to_dict(self) -> dict:
        """Every value by stage, JSON-ready (the ``"settings"`` of the ``stabilise`` JSON).

        Returns
        -------
        dict
            ``{stage: {name: value}}``; tuples as lists.
        """
        return {
            name: {k: list(v) if isinstance(v, tuple) else v for k, v in part.items()}
            for name, part in asdict(self).items()
        }


#: the defaults, shared by the functions that can also be called outside the pipeline
DEFAULTS = SelectionSettings()


@dataclass(frozen=True, repr=False)
class SweepSettings(_Settings):
    """The numbers of the stabilisation sweep (:func:`armaxmodal.stabilisation_diagram`), which runs
    before any selection and so stands beside :class:`~armaxmodal.modes.settings.SelectionSettings`,
    not in it; the JSON reports what they made (``orders_na``, ``nk``).

    Attributes
    ----------
    tol : float
        A sweep fit stops when an iteration lowers the loss by less than this fraction (a tenth
        of its statistical resolution, 1/N, for records up to 10^4 samples): enough to place
        poles. The fits whose estimates are reported are finished to ``fit_armax``'s default.
    nk_search : tuple of int
        The input delays searched (non-causal taps for band-limited data).
    nk_extension : int
        When the best delay is the most non-causal searched, this many more are tried, again while the
        choice stays at the end, down to the most non-causal delay the record supports at the sweep's
        top order (``diagram.deepest_delay``).
    delay_choice_orders : tuple of int
        The middle orders at which the delay is chosen (jointly with the order: ``choose_nk``).
    delay_choice_iterations : int
        The delay choice's fits' iteration cap; the sweep continues those of the chosen delay.
    samples_per_parameter : int
        Samples the record must hold per parameter of one sensor's model (about 3 na + 1 - nk)
        at the sweep's top order: fewer, and the fits describe the noise (and take minutes each).
    default_orders : tuple of int
        The orders swept when none are given, capped at what the record supports.

    See Also
    --------
    armaxmodal.stabilisation_diagram : The sweep they set.
    armaxmodal.modes.settings.SelectionSettings : The selection's thresholds.

    Examples
    --------
    >>> from armaxmodal.modes.settings import SWEEP
    >>> SWEEP.nk_search, SWEEP.delay_choice_orders, (min(SWEEP.default_orders), max(SWEEP.default_orders))
    ((0, -1, -2, -3, -4, -5, -6), (8, 10, 12), (2, 30))
    """

    tol: float = 1e-5
    nk_search: tuple[int, ...] = tuple(range(0, -7, -1))
    nk_extension: int = 3
    delay_choice_orders: tuple[int, ...] = (8, 10, 12)
    delay_choice_iterations: int = 8
    samples_per_parameter: int = 20
    default_orders: tuple[int, ...] = tuple(range(2, 31, 2))

    @property
    def min_default_top(self) -> int:
        """A default sweep capped below the delay choice's lowest order is refused: the record
        cannot support the fits that choose its delay (8 was a number of its own until 2026-12-07)."""
        return min(self.delay_choice_orders)


SWEEP = SweepSettings()  #: the sweep's numbers
