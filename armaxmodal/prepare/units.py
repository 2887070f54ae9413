"""An output recorded in other units than the rest (mg among m/s², g among m/s², ...).

Below its first mode a base-excited structure moves with its base: every absolute-
acceleration output reads the base acceleration, ``|T| = 1 + O(w^2)``, whatever its place
on the structure. An output whose quasi-static transmissibility is 102 while the others read
1.0 is in mg where they are in m/s². The modal frequencies do not care, but everything that
compares sensors does: the shape comparisons of the stabilisation criterion and of the
merging of split modes are dominated by the big channel (on the supine fixture with the head
in mg, two of the four modes were merged away with no warning), and the shapes and the
inverse problem's residues come out wrong by that factor.

The check needs a quasi-static band (the lowest coherent lines, where at least half of the
other outputs read ``|T|`` within ``armaxmodal.prepare.delay.QUASI_STATIC_MAGNITUDE`` of 1);
without one (a force input, a ride starting above the first mode) it says nothing. When the
ratio matches a unit conversion within ``UNIT_MATCH``, :func:`~armaxmodal.prepare.prepare`
converts the channel by that exact factor (by the measured ratio where two conversions are
that near, mg and Gal) and says so; otherwise the warning stands alone.
"""

from __future__ import annotations

import numpy as np

from armaxmodal.prepare.delay import QUASI_STATIC_MAGNITUDE, transmissibility_spectra
from armaxmodal.quality_warnings import QualityWarning, not_run
from armaxmodal.recording import Recording
from armaxmodal.stats import QUASI_STATIC_COHERENCE

__all__ = ["unit_mismatch", "unit_conversion", "UNIT_CONVERSIONS"]

G = 9.80665
#: an output reading this many times the others' quasi-static level is in other units
#: (quasi-static |T| of consistent outputs: 0.96-1.13 on the fixtures; a mode's dynamic
#: amplification below it stays far under 3x)
MISMATCH_RATIO = 3.0
#: the quasi-static lines used: the lowest this many excited, coherent ones
QUASI_STATIC_LINES = 8
#: a measured ratio names a conversion when within this relative distance of it
UNIT_MATCH = 0.05
#: ratio (this output over the others) -> what it means
UNIT_CONVERSIONS = {
    1000.0 / G: "mg where the others are in m/s²",
    G / 1000.0: "m/s² where the others are in mg",
    1.0 / G: "g where the others are in m/s²",
    G: "m/s² where the others are in g",
    1000.0: "a unit 1000 times smaller than the others' (mg against g, mm/s² against m/s²)",
    1e-3: "a unit 1000 times larger than the others' (g against mg, m/s² against mm/s²)",
    100.0: "cm/s² (Gal) where the others are in m/s²",
    1e-2: "m/s² where the others are in cm/s² (Gal)",
}


def unit_conversion(ratio: float) -> tuple[float, str] | None:
    """What to divide an output by whose quasi-static ratio to the others is ``ratio``, and
    why: the unit conversion within ``UNIT_MATCH`` of it, or the measured ratio itself
    when several are (mg and Gal differ by 2 %, within the ratio's own scatter of 1-2 %);
    None when no conversion is near."""
    near = _near_conversions(ratio)
    if len(near) == 1:
        return near[0]
    if near:
        options = " or ".join(f"{meaning} ({factor:.5g})" for factor, meaning in near)
        return ratio, f"{options}: the record cannot tell these apart, so the measured ratio is used"
    return None


def _near_conversions(ratio: float) -> list[tuple[float, str]]:
    """The unit conversions within UNIT_MATCH of ``ratio``: ``(factor, meaning)`` each."""
    return [(factor, meaning) for factor, meaning in UNIT_CONVERSIONS.items() if abs(ratio / factor - 1) <= UNIT_MATCH]


def _quasi_static_lines(recording: Recording) -> np.ndarray | None:
    """Each output's ``|T|`` on the lowest excited lines coherent on most outputs,
    (QUASI_STATIC_LINES, K), or None when the record has too few such lines."""
    spectra = transmissibility_spectra(recording)
    if spectra is None:
        return None
    f, h, coh, excited, _ = spectra
    lines = np.flatnonzero(excited & (f > 0) & (np.median(coh, axis=1) >= QUASI_STATIC_COHERENCE))
    if lines.size < QUASI_STATIC_LINES:
        return None
    return np.abs(h[lines[:QUASI_STATIC_LINES]])


def unit_mismatch(recording: Recording) -> list[QualityWarning]:
    """``unit_mismatch`` warnings: outputs whose quasi-static transmissibility is
    :data:`MISMATCH_RATIO` times or more away from that of the other outputs, which read 1
    (see the module docstring), or the input when every output reads the same flat
    multiple of it that a unit conversion explains (:func:`_input_in_other_units`).
    ``value`` is the measured ratio."""
    lines = _quasi_static_lines(recording)
    if lines is None:
        why = f"fewer than {QUASI_STATIC_LINES} excited lines below the first mode coherent on most outputs"
        return [not_run("unit_mismatch", recording.sensors, why)]
    gains = np.median(lines, axis=0)
    found = _input_in_other_units(recording, lines, gains)
    if found or len(recording.sensors) < 2:
        return found
    lo, hi = QUASI_STATIC_MAGNITUDE
    for k, name in enumerate(recording.sensors):
        others = np.delete(gains, k)
        static = others[(others >= lo) & (others <= hi)]
        if 2 * static.size < others.size or not static.size:
            continue  # no quasi-static band the others agree on: nothing to compare with
        ratio = float(gains[k] / np.median(static))
        if 1.0 / MISMATCH_RATIO < ratio < MISMATCH_RATIO:
            continue
        match = unit_conversion(ratio)
        found.append(
            QualityWarning(
                "unit_mismatch",
                (name,),
                f"'{name}' reads {ratio:.4g} times the other outputs below the first mode ({gains[k]:.4g} times "
                f"the input, the others {static.min():.3g}-{static.max():.3g}), where a base-excited structure "
                "moves with its base: "
                + (
                    f"it is in {match[1]}."
                    if match
                    else "it is in other units or scaled wrongly; shapes and the mode selection compare it "
                    "with the others at that scale. Convert it and rerun."
                ),
                ratio,
            )
        )
    return found


#: every output's quasi-static |T| within this factor over the lines (a base-excited
#: structure: 1.02-1.05 on the fixtures and the shake-table frames; a force input's
#: acceleration grows as the frequency squared: 1.2-4.0 on the F-16)
FLAT = 1.1


def _input_in_other_units(recording: Recording, lines: np.ndarray, gains: np.ndarray) -> list[QualityWarning]:
    """A ``unit_mismatch`` warning on the input when every output reads the same flat
    quasi-static multiple of it (outputs within QUASI_STATIC_MAGNITUDE's spread of each
    other, each flat within FLAT), at least MISMATCH_RATIO away from 1 and within
    UNIT_MATCH of a unit conversion: the input and the outputs are in different units.
    Frequencies and damping do not depend on it; residues, and the masses the inverse
    problem draws from them, are off by that factor. Reported, not converted."""
    lo, hi = QUASI_STATIC_MAGNITUDE
    ratio = float(np.median(gains))
    agree = gains.max() / gains.min() <= hi / lo and np.all(lines.max(axis=0) <= FLAT * lines.min(axis=0))
    if not agree or 1.0 / MISMATCH_RATIO < ratio < MISMATCH_RATIO:
        return []
    near = _near_conversions(ratio)
    if not near:
        return []
    named = [m.replace("the others are", "the input is").replace("the others'", "the input's") for _, m in near]
    meaning = " or ".join(m + (f" ({f:.5g})" if len(near) > 1 else "") for (f, _), m in zip(near, named, strict=True))
    return [
        QualityWarning(
            "unit_mismatch",
            (recording.input_name,),
            # the finding first: the terminal shows a note's first clauses
            f"the outputs are in {meaning}: every output reads {ratio:.4g} times the input "
            f"'{recording.input_name}' below the first mode ({gains.min():.4g}-{gains.max():.4g}), where a "
            "base-excited structure moves with its base. Frequencies, damping and shapes do not change; residues "
            "and the masses drawn from them are off by that factor. Convert one side and rerun.",
            ratio,
        )
    ]
