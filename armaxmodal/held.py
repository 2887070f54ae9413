"""``held_samples``: a channel recorded at a lower rate and held (forward-filled) to the
record's rate.

Loggers that join devices on one time base repeat a slower channel's last value until its
next sample (pandas' ``ffill`` does the same). Such a channel holds nothing above half its
own rate, and its steps put images there; pooled with the others it bends the shared poles
(the supine ride with head held at half rate lost two of its four modes without a word).

The test: a quantised or slow channel repeats values too, but at no particular phase. A held
channel repeats at the same phases of a k-sample cycle (k = 2 for half rate; for 100 Hz held
to 120 Hz, once every 6 samples at one phase). So the zero steps' positions modulo k are
tested for uniformity (chi-square, k - 1 degrees of freedom) for every k up to
:data:`MAX_CYCLE`; the channel's own rate is the record's times its share of non-zero steps.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .quality import QualityWarning
from .recording import Recording

__all__ = ["held_channels", "held_samples", "HeldChannel", "MAX_CYCLE"]

#: longest repeat cycle tested, samples
MAX_CYCLE = 16
#: family-wise level over the cycles and channels tested
HELD_ALPHA = 1e-6
#: fewest repeated samples, as a share of the steps, worth naming (a few repeats at one
#: phase change nothing the fit sees)
MIN_REPEAT_SHARE = 0.1


class HeldChannel(NamedTuple):
    """A held channel: its repeat cycle (samples), its own rate (Hz: the record's rate times
    its share of non-zero steps), that share's complement and the test's p-value."""

    name: str
    cycle: int
    own_rate_hz: float
    repeat_share: float
    p: float


def _repeat_cycle(x: np.ndarray, n_tests: int) -> tuple[int, float] | None:
    """``(k, p)``: the cycle the zero steps of ``x`` keep to, when their phases modulo some
    k are beyond chance (Bonferroni over ``n_tests``); else None. A multiple of the true
    cycle scores as high, so the shortest cycle within 10 % of the best score is named."""
    from scipy.special import chdtrc  # chi-square survival function without scipy.stats' import

    zero = np.flatnonzero(np.diff(x) == 0)
    steps = x.size - 1
    if steps < 4 * MAX_CYCLE or zero.size < MIN_REPEAT_SHARE * steps:
        return None
    scores = {}
    for k in range(2, MAX_CYCLE + 1):
        counts = np.bincount(zero % k, minlength=k)
        expected = zero.size / k
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
    """Every channel (input first) whose repeated samples keep to a cycle."""
    names = (recording.input_name, *recording.sensors)
    data = np.column_stack([recording.base, recording.response])
    n_tests = (MAX_CYCLE - 1) * len(names)
    found = []
    for name, x in zip(names, data.T, strict=True):
        hit = _repeat_cycle(x, n_tests)
        if hit is not None:
            share = float(np.mean(np.diff(x) == 0))
            found.append(HeldChannel(name, hit[0], recording.fs * (1 - share), share, hit[1]))
    return found


def _p_text(p: float) -> str:
    return f"= {p:.1g}" if p > 0 else "< 1e-300"


def held_samples(recording: Recording) -> list[QualityWarning]:
    """One ``held_samples`` warning per held channel, with its own rate and what to do."""
    out = []
    for name, cycle, own_rate, share, p in held_channels(recording):
        top = 0.4 * own_rate
        role = "the input" if name == recording.input_name else "output"
        out.append(
            QualityWarning(
                "held_samples",
                (name,),
                f"{role} '{name}' repeats its previous value on {100 * share:.0f} % of its steps, always at the "
                f"same phases of a {cycle}-sample cycle (chi-square p {_p_text(p)}): it was sampled at about "
                f"{own_rate:.3g} Hz and held to {recording.fs:g} Hz, so it carries nothing above "
                f"{own_rate / 2:.3g} Hz but the images of its steps. Analyse below {top:.3g} Hz "
                f"(--band LO:{top:.3g}) or re-export it at its own rate.",
                own_rate,
            )
        )
    return out
