"""The notes every stage returns: a data-quality or method finding with its code, the
channels it concerns, a sentence with the measured number, and that number. They travel with
a result into its JSON (``warnings``) and the command line's ``note:`` lines."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["QualityWarning", "UNCERTAIN_CODES", "WARNING_CODES", "not_run"]

WARNING_CODES = (
    "duplicate_channel",
    "inverted_sensor",
    "sensor_delay",
    "narrowband_input",
    "clipping",
    "dropped_packet",
    "gap_filled",
    "offset_removed",
    "offset_step",
    "drift",
    "trend_removed",
    "resampled",
    "model_error_dominates",
    "nk_at_search_edge",
    "unexplained_peak",
    "damping_unresolved",
    "split_merged",
    "no_modes",
    "incoherent_output",
    "unit_mismatch",
    "periodic_disturbance",
    "stuck_samples",
    "oversampled",
    "held_samples",
    "mode_not_needed",
    "modes_do_not_explain_frf",
    "orders_capped",
    "refit_failed",
    "check_not_run",
    "mode_count",
    "count_undecided",
    "modes_not_separated",
    "pick_not_supported",
)

#: the codes that make a passing selection ``uncertain``: the nested tests do not decide the
#: number of modes, two modes lie closer than the record separates, or the preparation found a
#: fault that moves modes (measured on damaged copies of the supine ride: a drift put 13.5 Hz at
#: 13.96, a hum at 12.5 Hz at 14.33, a pelvis stuck for 53 samples at 14.69, a head held at
#: 30 Hz at 13.75, each outside its interval)
UNCERTAIN_CODES = (
    "count_undecided",
    "modes_not_separated",
    "pick_not_supported",
    "drift",
    "periodic_disturbance",
    "stuck_samples",
    "held_samples",
)

@dataclass(frozen=True)
class QualityWarning:
    """One data-quality finding: ``code`` (see :data:`WARNING_CODES`), the channels it
    concerns, a sentence with the measured number, and that number (``value``, its unit in
    the message)."""

    code: str
    channels: tuple[str, ...]
    message: str
    value: float | None = None

    def __post_init__(self):
        if self.code not in WARNING_CODES:
            raise ValueError(f"unknown warning code {self.code!r}; expected one of {WARNING_CODES}.")

    def to_dict(self) -> dict:
        value = None if self.value is None or not np.isfinite(self.value) else float(self.value)
        return {"code": self.code, "channels": list(self.channels), "message": self.message, "value": value}


def not_run(check: str, channels: tuple[str, ...], why: str) -> QualityWarning:
    """The note that a check could not run on ``channels`` (a check that says nothing has run
    and found nothing)."""
    return QualityWarning("check_not_run", tuple(channels), f"{check} not tested on {', '.join(channels)}: {why}")
