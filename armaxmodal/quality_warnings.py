"""The warnings every stage returns: a data-quality or method finding with its code, the
channels it concerns, a sentence with the measured number, and that number. They travel with
a result into its JSON (``warnings``) and the command line's ``warning [code]:`` lines."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["CODES", "QualityWarning", "UNCERTAIN_CODES", "WARNING_CODES", "WarningCode", "not_run"]


@dataclass(frozen=True)
class WarningCode:
    """What one warning code means: where it is raised (``stage``), what was measured, what the
    product does about it, what the user should do, and whether it makes a passing selection
    ``uncertain``. The docs' warning page is generated from these (``docs/conf.py``)."""

    code: str
    stage: str
    measured: str
    done: str
    advice: str
    uncertain: bool = False


#: Every warning code, in the order the stages raise them. ``uncertain``: the codes that make a
#: passing selection ``uncertain`` -- the nested tests do not decide the number of modes, two
#: modes lie closer than the record separates, or the preparation found a fault that moves modes
#: (measured on damaged copies of the supine ride: a drift put 13.5 Hz at 13.96, a hum at 12.5 Hz
#: at 14.33, a pelvis stuck for 53 samples at 14.69, a head held at 30 Hz at 13.75, each outside
#: its interval; two rows dropped at 50 s of a five-segment body's 120 s ride, bridged, put its
#: 7.411 Hz at 7.379 [7.360, 7.399] and hid a mode the clean ride's count names).
CODES: tuple[WarningCode, ...] = (
    WarningCode(
        "duplicate_channel",
        "preparation",
        "an output equal or proportional to another channel (1 − |r| ≤ 1e-6)",
        "the copy is left out of the fit",
        "Check the export: a channel written twice, or two sensors on one signal. Nothing to do if it was meant.",
    ),
    WarningCode(
        "inverted_sensor",
        "preparation",
        "quasi-static transmissibility near −1 (on every output of several: the input is named)",
        "reported; shapes keep the sign",
        "Check the sensor's mounting and sign convention; flip the channel if it was mounted upside down.",
    ),
    WarningCode(
        "sensor_delay",
        "preparation",
        "a linear phase of the quasi-static transmissibility (below the first mode it is 1 + O(ω²) with an O(ω³) "
        "phase), in ms with its interval (Student-t on the larger of the fit's and a delete-two-segments jackknife's "
        "standard deviation: Hann-windowed lines are correlated, and the fit's alone was 1.3–1.6× narrow over 40 "
        "rides); reported from ¾ sample (a held input shows ½)",
        "whole samples aligned",
        "If the delay is a logger's, fix the time stamps at the source; `diagnose` times it to a fraction of a sample, "
        "and names a delay that grows through the record (`clock_drift`: the logger's clock runs off) with its rate.",
    ),
    WarningCode(
        "narrowband_input",
        "preparation",
        "input lines within 10 dB of the peak span < 0.3 × the peak frequency",
        "reported",
        "Modes away from the input's band rest on weak excitation: use a broadband ride, or trust only the modes "
        "inside the band.",
    ),
    WarningCode(
        "clipping",
        "preparation",
        "at least 5 samples on a channel's extreme value, more than the values just inside it occur (Poisson p < 1e-4,"
        " or < 0.01 with two in a row: a peak sampled a few times per period clips in single samples, a coarse "
        "quantiser dwells on every level; the measured records here: p = 1)",
        "reported",
        "Re-record with a wider range; `diagnose` fills clipped output samples, a clipped input cannot be repaired.",
    ),
    WarningCode(
        "dropped_packet",
        "preparation",
        "packets missing in an IMU export, or rows missing from a CSV's time column",
        "bridged (≤ 3, or as many as `--fill-gaps` allows) or refused; the bridged samples are wrong in every "
        "channel at one instant and enter the fit as data, which moves modes (`uncertain`)",
        "Cut the record at the gap and analyse the longer piece, or bridge longer gaps with `--fill-gaps SECONDS`.",
        uncertain=True,
    ),
    WarningCode(
        "gap_filled",
        "preparation",
        "missing cells (a dropped packet written as empty) filled on request, `--fill-gaps SECONDS` / "
        "`read_recording(fill_gaps=...)`",
        "filled by linear interpolation, each run named by its rows; a longer run, or one at the start or end, is "
        "refused",
        "Nothing if the gaps are short against the modes' periods; the intervals are widened for the filled samples.",
    ),
    WarningCode(
        "empty_columns_dropped",
        "preparation",
        "unnamed columns at the end of a CSV's lines with no value in any row (`,,,,` after every line, as "
        "spreadsheets export empty columns)",
        "left out; an unnamed column that holds data is refused by its number",
        "Nothing: informative.",
    ),
    WarningCode(
        "time_rounded",
        "preparation",
        "a CSV's time column whose steps are uneven only by its printed rounding (60 Hz with 4 decimals steps 0.0166 "
        "and 0.0167 s): every stamp within a printed digit of a uniform grid",
        "read at the rate of the column's whole span (60.000 Hz); jitter or a gap beyond the rounding is refused as "
        "before",
        "Nothing: informative. Print the time with more decimals to keep it exact.",
    ),
    WarningCode(
        "offset_removed",
        "preparation",
        "each channel's mean (default; `--detrend linear` for a line)",
        "removed",
        "Nothing: a constant (gravity on an accelerometer, a bias) is removed.",
    ),
    WarningCode(
        "offset_step",
        "preparation",
        "a level shift (a sensor's offset jumping mid-record: re-zeroing, a knock) that explains over 1 % of a "
        "channel's variance (measured records stay under 0.03 %, an earthquake's onset included) and happens at once: "
        "the means of the windows (2 % of the record) either side differ by ≥ 4 robust SDs of such differences along "
        "the channel (a drift reads 0.9–2.5, a velocity channel's wander 1.1–3.6, a shift of 0.3 × RMS 4.8–5.0); "
        "binary segmentation, up to 3 per channel; its size (also × RMS) and time",
        "removed with the default or linear detrend (the level before it continues); reported only with `--detrend "
        "none` and in `diagnose`. Before, +0.8 on the supine pelvis from 60 s moved the 13.5 Hz mode to 14.66 Hz "
        "outside its interval, with a drift warning whose advice (`--detrend linear`) left it at 14.56 Hz; +0.28 lost "
        "that mode",
        "Find what happened at that time (re-zeroing, a knock); `diagnose` names the step (`level_shift`) with its "
        "time and size and their intervals, and takes it out.",
    ),
    WarningCode(
        "drift",
        "preparation",
        "a line explaining more than 1 % of a channel's variance after its mean was removed (a drifting sensor, a slow"
        " tilt)",
        "reported with each channel's rate and share of variance; the modes are biased while it stays",
        "Rerun with `--detrend linear`, or run `diagnose`, which fits the drift.",
        uncertain=True,
    ),
    WarningCode(
        "trend_removed",
        "preparation",
        "each channel's mean (default; `--detrend linear` for a line)",
        "removed",
        "Nothing: informative.",
    ),
    WarningCode(
        "resampled",
        "preparation",
        "the band (`--band`, or the input's excited band) ends far below Nyquist",
        "polyphase anti-alias resampling to about band/0.4 (F-16: 400 → 40 Hz)",
        "Nothing; give `--band` to choose the analysis band yourself.",
    ),
    WarningCode(
        "model_error_dominates",
        "preparation",
        "each mode refitted on three disjoint thirds; their spread beyond the statistical interval (χ², 1 % "
        "family-wise)",
        "the 95 % interval widened to the thirds' t-interval",
        "The record's thirds disagree about the mode: run `diagnose` to find the effect (a nonlinearity, a change in "
        "time, a sensor's gain change or clock drift).",
    ),
    WarningCode(
        "nk_at_search_edge",
        "preparation",
        "the BIC-chosen delay at the most non-causal delay the record supports for the sweep's top order (the "
        "search, 0 … −6, widens by 3 while its choice sits at its end)",
        "reported",
        "Check the input's timing (a delay beyond the search); give `--orders` with the delay you expect, or run "
        "`diagnose`.",
    ),
    WarningCode(
        "unexplained_peak",
        "selection; identify too",
        "a coherent (γ² ≥ 0.8) FRF peak, a third above both valleys, at least 5 % of the sensor's largest response and"
        " spanning the lines a mode spans, with no selected mode within 2ξf (or 1 %)",
        "reported with its frequency (F-16 level 1: 4.03 Hz, a landing-gear mode the selection left out)",
        "Widen `--orders` or set `--modes`, or `--pick` the peak to see what the record says of it; run `diagnose` if "
        "it is a disturbance.",
    ),
    WarningCode(
        "undriven_resonance",
        "selection",
        "a column of the diagram's poles with negative damping at 3 orders or more, beside a clear, coherent H1 peak "
        "(within 5 %) that no reported mode is near (Painter Street 2021-12-20: 4.34 Hz at 10 orders, the H1 at "
        "4.25 Hz)",
        '`"quality": "uncertain"` at best: the frequency is named, no mode is reported (its damping has no estimate)',
        "Record the motion of the structure's other supports (a bridge's abutments) and give it as the input, or "
        "take this mode's frequency from the H1; check the input's timing if the outputs may lead it.",
        uncertain=True,
    ),
    WarningCode(
        "damping_unresolved",
        "selection",
        "a mode whose damping interval (taken on log ξ, it never reaches zero) spans a factor e² or more, where the "
        "symmetric interval of the same deviation would reach zero, or reaches critical damping; or whose damping "
        "estimate is not positive at some orders of the sweep",
        "kept when the measured FRF has a clear coherent peak there; its frequency stands, its damping is known only "
        "to its interval, and the note says why (too light for the record, the thirds disagree, or the equally good "
        "models or the two estimators disagree)",
        "Quote the damping with its interval; a longer record or more excitation near the mode narrows it, and "
        "`diagnose` looks for what the thirds or the models disagree about.",
    ),
    WarningCode(
        "split_merged",
        "selection",
        "two modes whose half-power bands overlap, and the modal-model check (below) that does not need the weaker "
        "once the other's pole is refitted in its place: no output's misfit rises by 5 % with p < 1 %",
        "the less supported one dropped, with the rise and p",
        "Nothing: informative; `--pick` both frequencies to see what the record says of each.",
    ),
    WarningCode(
        "no_modes",
        "selection",
        "no cluster of the diagram is a mode: the shared poles in the band, how many were rejected and for what, and "
        "how many orders the best-supported cluster of the rest holds against what a mode needs",
        'a result, not a stop: no modes, `"quality": "poor"`, the diagram, pole table and JSON written; a study '
        "lists the recording among its failures",
        "Widen the band, extend the order range, or check that the input excites the structure.",
    ),
    WarningCode(
        "incoherent_output",
        "preparation",
        "an output's coherence with the input below 0.3 both averaged over the input's spectrum and over the "
        "output's own, the share of its power the input explains (response sensors: 0.63–1.00 over the input's "
        "spectrum on every measured record here; independent noise 0.07; a 1 %-damped chain's sensors, which move "
        "only near their resonances, 0.17–0.30 over the input's spectrum but far more over their own)",
        "left out of the fit while another output responds (pooled, a temperature channel beside the supine ride's "
        "sensors moved its 13.7 Hz mode to 15.0 Hz; left out, the modes are the clean ride's to the last digit); when "
        "no output responds, all are kept and the message says the modes found are not the structure's (a record of "
        'pure noise gave two "modes" with intervals and no warning before)',
        "Check that the channel is a mounted response sensor (not a temperature or a trigger); leave it out with "
        "`--outputs`.",
    ),
    WarningCode(
        "unit_mismatch",
        "preparation",
        "an output whose quasi-static transmissibility is ≥ 3× (or ≤ ⅓) that of the other outputs, which read 1 "
        "(consistent outputs: 0.96–1.13 on the fixtures); the ratio and the unit conversion it matches within 5 % On "
        "the input: every output reading the same flat quasi-static multiple of the input (within 1.1× over the lines;"
        " a force input's grows as f²: 1.2–4× on the F-16) that a unit conversion explains within 5 % (base in g, "
        "outputs in m/s²: 9.86)",
        "divided by the conversion factor (by the measured ratio where two conversions are that near: mg 101.97 and "
        "Gal 100 differ by less than the ratio's 1–2 % scatter); a ratio matching no unit is only reported. Before, "
        "the head in mg dominated every shape comparison and two of the four supine modes were merged away with no "
        "warning On the input: reported on the input: frequencies, damping and shapes do not change, residues and the "
        "masses drawn from them do",
        "Give every channel in one unit (m/s²): the conversion named is the likely one.",
    ),
    WarningCode(
        "periodic_disturbance",
        "preparation",
        "after the sweep: a shared pole undamped (|ξ| < 0.002) with a residue under 1 % of the strongest pole's at ≥ "
        "40 % of the orders, i.e. a line the input does not drive (a 0.3 m/s² hum on the supine fixture's legs: 12.500"
        " Hz, ξ ≤ 1.5e-4 at 11 of 15 orders; none on any measured record here, nor on a structure damped at 0.07 %), "
        "with the sensors whose own sweep shows it and whether the input carries the line too (its PSD ≥ 10 dB above "
        "the neighbouring lines: pickup on every channel)",
        "reported, pointing to `diagnose`, which fits the line; before, the hum cost the 13.5 Hz mode with no word",
        "Run `diagnose`, which fits the line; find its source (mains hum, a pump) and shield or remove it.",
        uncertain=True,
    ),
    WarningCode(
        "stuck_samples",
        "preparation",
        "a run of equal samples away from the channel's extremes, weighed against the channel's own rate of repeats (p"
        " < 1 % over the channels; a dropout of 52 samples: p = 1e-193; a channel quantised to 0.3 × RMS, 15 % "
        "repeats: none); at the record's first or last sample only from 10 samples (a channel shifted into alignment "
        "repeats its first value a few times)",
        "reported with its start and length; `diagnose` fills it by prediction",
        "Look at the channel at the time named (a dropout, a disconnected or saturated sensor); cut that stretch, or "
        "run `diagnose`, which fills it.",
        uncertain=True,
    ),
    WarningCode(
        "oversampled",
        "selection; identify too",
        "every mode found lies below 10 % of the Nyquist frequency of the analysis rate (the measured records here: "
        "28–66 %), because the input excites far above the structure and the rate was kept",
        "reported with the band to rerun with (2.5 × the highest mode found) and the rate it gives. The supine model "
        "at 1 kHz under a 0.5–400 Hz ride: one of four modes (16.34 Hz), no word before; with the suggested `--band "
        "0:41` (111 Hz): 5.83, 8.32, 13.44, 16.22 Hz against 5.83, 8.31, 13.50, 16.25, in 3.3 s instead of 10.3 s. "
        "`identify` on that record gave 5.76, 8.48, 16.33 Hz with intervals far narrower than their errors, fits of "
        "−66 % to 47 %, and no warning; now it warns",
        "Rerun with the `--band` the warning suggests.",
    ),
    WarningCode(
        "held_samples",
        "preparation",
        "a channel sampled at a lower rate and held (forward-filled) or linearly interpolated to the record's: its "
        "repeated samples (or those on the line through their neighbours, second difference ≤ 1e-4 of its RMS) keep to"
        " the phases of a k-sample cycle (χ² of their positions mod k, k ≤ 16, p < 1e-6 over the channels and cycles, "
        "repeats on ≥ 10 % of the steps; a quantiser's or a failed read's repeats fall at no phase); its own rate is "
        "the record's times its share of changing samples (head held at 30 Hz on the 60 Hz supine ride: 2-sample "
        "cycle, 30.0 Hz; 50 Hz held to 60 Hz: 6-sample cycle)",
        "an output is left out of the fit while one at the record's rate remains, unless `--band` ends below 0.4 of "
        "its own rate (the resampling filter then removes its images); pooled, head held or interpolated at half rate "
        "cost the supine ride two of its four modes with no warning",
        "Record every channel at the record's rate, or give `--band` below 0.4 of the held channel's own rate.",
        uncertain=True,
    ),
    WarningCode(
        "mode_not_needed",
        "selection",
        "a stable cluster whose mode the modal-model check does not need (leaving it out raises no output's misfit by "
        "5 % with p < 1 %) and that the count, offered it as an addition, leaves out: a spurious pole of noise, a "
        "nonlinearity or leakage (stiff 1-storey El Centro: 42.9 Hz, +0.6 %)",
        "left out, with the rise and p",
        "Nothing: informative; `--pick` the frequency if you know a mode is there.",
    ),
    WarningCode(
        "modes_do_not_explain_frf",
        "selection; identify too",
        "the modal-model check fails: some output's model error (its misfit beyond the H1's random error) above 50 %, "
        "or a mode with no coherent H1 line near it (unconfirmed)",
        'the outputs and the bands of misfit named, `"quality": "poor"` in the JSON, the CLI\'s last line says so, '
        "the figure shades the bands",
        "Treat the modes as unconfirmed: widen `--orders`, check the outputs named, or run `diagnose`.",
    ),
    WarningCode(
        "orders_capped",
        "sweep",
        "the default orders 2–30 need more samples than the record has (20 a parameter)",
        "capped at what it supports; orders the user typed are refused as before",
        "Record longer for higher orders, or give `--orders` within what the record supports.",
    ),
    WarningCode(
        "refit_failed",
        "selection",
        "the frequency-domain refit could not be made (too few lines in the band, a degenerate basis)",
        "the ARMAX fit's values (or an earlier refit's) are reported, and the note says so",
        "Widen the band or record longer; the ARMAX values stand meanwhile.",
    ),
    WarningCode(
        "check_not_run",
        "preparation",
        "a check that could not run, and why: `sensor_delay`/`inverted_sensor` on outputs without quasi-static lines "
        "near ±1 (a force input such as the F-16's, an output in other units, a sine ride), `unit_mismatch` without "
        "such lines, `narrowband_input` or `incoherent_output` on a record too short",
        "reported; a check that says nothing has run and found nothing",
        "Nothing: the check could not run on this record, so it has found nothing.",
    ),
    WarningCode(
        "mode_count",
        "selection",
        "a step of the nested tests of the maximum-likelihood modal model ([method](../method.md)): a mode left out, "
        "added or split because the information criterion (BIC) falls, with by how much; an addition the whole record "
        "accepts but one of its halves does not; poles the model needs beyond the band (an upper residual) or damped "
        "beyond 0.6, which are not reported",
        "reported",
        "Nothing: informative; it says how the number of modes was reached.",
    ),
    WarningCode(
        "count_undecided",
        "selection",
        "removing the weakest mode (the rest refitted free), or adding the best candidate, moves BIC by less than 10 "
        '(Kass & Raftery\'s "very strong"); or a starting mode the count left out (carried by the free fit to '
        "where no mode is founded) while the H1 keeps a coherent peak no mode explains within 5 % of it (a bridge "
        "under an earthquake: the halves test is weak on a transient input); or a pole of the modal model beyond "
        "the band or damped beyond 0.6 whose 95 % interval reaches back into the band and below 0.6 (a heavily "
        "damped mode near the band's top)",
        '`"quality": "uncertain"`: the weakest mode, or one more near the frequency named, is tentative',
        "Treat the mode named as tentative: compare another record of the structure, or `--pick` it to see what the "
        "record says; for a pole just past the band, excite and fit a band that reaches past it (`--band`).",
        uncertain=True,
    ),
    WarningCode(
        "model_inadequate",
        "selection",
        "the modal model the criterion and the halves chose misfits the record beyond its noise: some output's "
        "residual power exceeds 1.25 times the noise the local polynomial method measures in that residual "
        "(0.97–1.02 on simulated bodies and light chains; 1.3–35 on the bridge and shake-table records that "
        "misfit, 32–2,056 on the F-16's multisine)",
        "the count runs again under one stated rule: a mode it adds must also stand in a stable column of the "
        "diagram (the likelihood of a wrong model buys ghost modes); what that rule refused is named; a reported "
        "mode without a column is `count_undecided`",
        "Read the modes as those the record and the diagram agree on; look for what the model lacks with "
        "`armaxmodal diagnose` (a second input, a delay, a nonlinearity).",
    ),
    WarningCode(
        "mode_beyond_band",
        "selection",
        "a pole of the maximum-likelihood modal model whose removal raises BIC by 10 or more, whose 95 % intervals "
        "lie wholly outside the band and below Nyquist in frequency and above zero in damping (at most 0.6), and whose "
        "half-power band f(1 ∓ damping) reaches into the band: a mode the record determines beyond the band (a "
        "body's 27.7 Hz mode under a ride to 24 Hz, the band ending at 25.7 Hz)",
        "not reported, since the modes reported are those of the band; named with its intervals (the JSON's "
        "`count` → `poles`, verdict `beyond_band`). The modes of the band were fitted with it in the model",
        "To report it, excite the structure past it and fit a band that holds it (`--band`; the band never "
        "reaches beyond the input's excited band).",
    ),
    WarningCode(
        "modes_not_separated",
        "selection",
        "two neighbouring modes whose frequencies' difference has a 95 % interval holding zero",
        "where the model's own intervals are that close and the shapes agree (MAC ≥ 0.8), the two poles are reported "
        "as one mode (the model refitted with one pole there) whose intervals cover both (the F-16 at its highest "
        "level: 6.356 and 6.395 Hz, 0.2 SD apart, reported as 6.387 Hz); otherwise both are reported. Either way "
        '`"quality": "uncertain"`',
        "Treat the pair as one resonance; a longer record or more sensors may separate them.",
        uncertain=True,
    ),
    WarningCode(
        "estimators_disagree",
        "selection",
        "the modal model's frequencies and damping ratios against the diagram's fit of the same modes (the ARMAX fit, "
        "or its band-limited refit): the sum of their squared standardised differences beyond its χ² 1 % point "
        "(Hausman's specification test; the F-16's multisine levels: 30–59 for 12 values, the point 26.2)",
        "every mode's 95 % interval covers both estimators' (`interval_covers_other_estimator` where that widens it): "
        "one of them is biased, by model error the two weight differently (a nonlinearity, the inter-sample "
        "behaviour, leakage) or by orders too low for a mode, and one record cannot say which",
        "Nothing if a structure like this is expected to be mildly nonlinear; otherwise run `diagnose` to find the "
        "effect, and compare a record at another excitation level.",
    ),
    WarningCode(
        "pick_not_supported",
        "selection (picks)",
        "without a picked mode (the others refitted free), BIC changes by less than 10: the record does not need it",
        '`"quality": "uncertain"`: the pick is tentative; pick another column of the diagram, or let the selection'
        " choose",
        "Pick another column of the diagram, or let the selection choose.",
        uncertain=True,
    ),
)
WARNING_CODES = tuple(c.code for c in CODES)
UNCERTAIN_CODES = tuple(c.code for c in CODES if c.uncertain)
#: the codes that make the verdict poor: the modes do not explain the record, or there are none
PROBLEM_CODES = ("no_modes", "modes_do_not_explain_frf")
#: besides the uncertain ones, the findings a user must act on: a fault of the data the product
#: reports but cannot set right, or a result it could not complete
ACT_ON_CODES = (
    "duplicate_channel",
    "inverted_sensor",
    "sensor_delay",
    "narrowband_input",
    "clipping",
    "offset_step",
    "model_error_dominates",
    "nk_at_search_edge",
    "unexplained_peak",
    "damping_unresolved",
    "incoherent_output",
    "unit_mismatch",
    "oversampled",
    "refit_failed",
    "mode_beyond_band",
)


def severity(code: str) -> str:
    """How a note moves the verdict, as the command line labels it.

    Parameters
    ----------
    code : str
        A warning code (``WARNING_CODES``).

    Returns
    -------
    str
        ``"problem"`` (the verdict is poor), ``"warning"`` (the verdict is uncertain, or the user
        must act on it) or ``"info"`` (said, and dealt with: a rounding read through, a
        resampling, how the count went).
    """
    if code in PROBLEM_CODES:
        return "problem"
    return "warning" if code in UNCERTAIN_CODES or code in ACT_ON_CODES else "info"


@dataclass(frozen=True)
class QualityWarning:
    """One data-quality finding: ``code`` (see ``WARNING_CODES``), the channels it
    concerns, a sentence with the measured number, and that number (``value``, its unit in
    the message); ``freq_hz``, the frequencies (Hz) it is about, if any (what the one-line
    summary of the notes names).

    See Also
    --------
    armaxmodal.prepare.check_quality : The record's checks.
    armaxmodal.ModeSelection : Carries the selection's notes.

    Examples
    --------
    >>> import armaxmodal as am
    >>> note = am.QualityWarning("offset_removed", ("head",), "the mean of head (0.31 m/s²) was removed", 0.31)
    >>> note.code, note.channels, note.value
    ('offset_removed', ('head',), 0.31)
    """

    code: str
    channels: tuple[str, ...]
    message: str
    value: float | None = None
    freq_hz: tuple[float, ...] = ()

    def __post_init__(self):
        if self.code not in WARNING_CODES:
            raise ValueError(f"unknown warning code {self.code!r}; expected one of {WARNING_CODES}.")
        object.__setattr__(self, "freq_hz", tuple(float(f) for f in self.freq_hz))

    def to_dict(self) -> dict:
        value = None if self.value is None or not np.isfinite(self.value) else float(self.value)
        freqs = [f for f in self.freq_hz if np.isfinite(f)]
        return {
            "code": self.code,
            "channels": list(self.channels),
            "message": self.message,
            "value": value,
            "freq_hz": freqs,
        }


def not_run(check: str, channels: tuple[str, ...], why: str) -> QualityWarning:
    """The note that a check could not run on ``channels`` (a check that says nothing has run
    and found nothing)."""
    return QualityWarning("check_not_run", tuple(channels), f"{check} not tested on {', '.join(channels)}: {why}")
