"""``held_samples``: a channel recorded at a lower rate and held (forward-filled) or linearly
interpolated to the record's rate.

Loggers that join devices on one time base repeat a slower channel's last value until its
next sample (pandas' ``ffill`` does the same). Such a channel holds nothing above half its
own rate, and its steps put images there; pooled with the others it bends the shared poles
(the supine ride with head held at half rate lost two of its four modes without a word).

The test: a quantised or slow channel repeats values too, but at no particular phase. A held
channel repeats at the same phases of a k-sample cycle (k = 2 for half rate; for 100 Hz held
to 120 Hz, once every 6 samples at one phase). So the zero steps' positions modulo k are
tested for uniformity (chi-square, k - 1 degrees of freedom) for every k up to
``MAX_CYCLE``; the channel's own rate is the record's times its share of non-zero steps.
A linearly interpolated channel does the same with its second differences: the filled
samples lie on the straight line through their neighbours.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.recording import Recording

__all__ = ["held_channels", "held_samples", "HeldChannel", "MAX_CYCLE"]

#: longest repeat cycle tested, samples
MAX_CYCLE = 16
#: family-wise level over the cycles and channels tested
HELD_ALPHA = 1e-6
#: fewest repeated samples, as a share of the steps, worth naming (a few repeats at one
#: phase change nothing the fit sees)
MIN_REPEAT_SHARE = 0.1


class HeldChannel(NamedTuple):
    """A channel filled in from a lower rate: ``how`` it was filled ("held": each value
    repeated; "interpolated": straight lines between its samples), its cycle (samples), its
    own rate (Hz: the record's rate times its share of samples that are its own), the share
    of filled samples and the test's p-value."""

    name: str
    how: str
    cycle: int
    own_rate_hz: float
    repeat_share: float
    p: float


#: a second difference this small against its RMS is a straight line through three samples
#: (what linear interpolation leaves, up to the digits a CSV kept); by chance it happens at
#: about 1e-4 of the samples
FLAT_TOLERANCE = 1e-4


def _filled_positions(x: np.ndarray) -> dict[str, np.ndarray]:
    """Sample positions that repeat their predecessor, and those on the straight line through
    their neighbours."""
    d2 = np.diff(x, 2)
    scale = float(np.sqrt(np.mean(d2**2))) if d2.size else 0.0
    return {
        "held": np.flatnonzero(np.diff(x) == 0),
        "interpolated": np.flatnonzero(np.abs(d2) <= FLAT_TOLERANCE * scale) if scale > 0 else np.array([], int),
    }


def _cycle(positions: np.ndarray, steps: int, n_tests: int) -> tuple[int, float] | None:
    """``(k, p)``: the cycle ``positions`` keep to, when their phases modulo some k are
    beyond chance (Bonferroni over ``n_tests``); else None. A multiple of the true cycle
    scores as high, so the shortest cycle within 10 % of the best score is named."""
    from scipy.special import chdtrc  # chi-square survival function without scipy.stats' import

    if steps < 4 * MAX_CYCLE or positions.size < MIN_REPEAT_SHARE * steps:
        return None
    scores = {}
    for k in range(2, MAX_CYCLE + 1):
        counts = np.bincount(positions % k, minlength=k)
        expected = positions.size / k
        stat = float(np.sum((counts - expected) ** 2) / expected)
        p = min(1.0, float(chdtrc(k - 1, stat)) * n_tests)
        if p < HELD_ALPHA:
            scores[k] = (stat, p)
    if not scores:
        return None
    top = max(stat for stat, _ in scores.values())
    k = min(k for k, (stat, _) in scores.items() if stat >= 0.9 * top)
    return k, scores[k][1]


def held_channels(recording: Recording) -> list[HeldChannel]:
    """Every channel (input first) whose repeated or interpolated samples keep to a cycle."""
    names = (recording.input_name, *recording.sensors)
    data = np.column_stack([recording.base, recording.response])
    n_tests = 2 * (MAX_CYCLE - 1) * len(names)
    found = []
    for name, x in zip(names, data.T, strict=True):
        for how, positions in _filled_positions(x).items():
            hit = _cycle(positions, x.size - 1, n_tests)
            if hit is not None:
                share = positions.size / (x.size - 1)
                found.append(HeldChannel(name, how, hit[0], recording.fs * (1 - share), share, hit[1]))
                break
    return found


def _p_text(p: float) -> str:
    return f"= {p:.1g}" if p > 0 else "< 1e-300"


_WHAT = {
    "held": ("repeats its previous value on {share:.0f} % of its steps", "held"),
    "interpolated": ("lies on the line through its neighbours at {share:.0f} % of its samples", "interpolated"),
}


def held_samples(recording: Recording) -> list[QualityWarning]:
    """One ``held_samples`` warning per filled-in channel, with its own rate and what to do."""
    out = []
    for name, how, cycle, own_rate, share, p in held_channels(recording):
        top = 0.4 * own_rate
        role = "the input" if name == recording.input_name else "output"
        what, verb = _WHAT[how]
        out.append(
            QualityWarning(
                "held_samples",
                (name,),
                f"{role} '{name}' {what.format(share=100 * share)}, always at the same phases of a {cycle}-sample "
                f"cycle (chi-square p {_p_text(p)}): it was sampled at about {own_rate:.3g} Hz and {verb} to "
                f"{recording.fs:g} Hz, so it carries nothing above {own_rate / 2:.3g} Hz but the images of its "
                f"filling. Analyse below {top:.3g} Hz (--band LO:{top:.3g}) or re-export it at its own rate.",
                own_rate,
            )
        )
    return out
