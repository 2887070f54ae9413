"""Every data-quality check run before a fit, in one call (the checks themselves live in
:mod:`armaxmodal.prepare.quality`, :mod:`~armaxmodal.prepare.delay`, :mod:`~armaxmodal.prepare.held` and
:mod:`~armaxmodal.prepare.units`)."""

from __future__ import annotations

from armaxmodal.prepare.delay import delay_and_inversion
from armaxmodal.prepare.held import held_samples
from armaxmodal.prepare.quality import (
    clipped_channels,
    duplicate_channels,
    incoherent_outputs,
    narrowband_input,
    stuck_channels,
)
from armaxmodal.prepare.units import unit_mismatch
from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.recording import Recording

__all__ = ["check_quality"]


def check_quality(recording: Recording) -> list[QualityWarning]:
    """Every pre-fit check on ``recording`` (see :mod:`armaxmodal.prepare.quality`).

    Parameters
    ----------
    recording : Recording
        The record as read (before any preparation).

    Returns
    -------
    list of QualityWarning
        The findings, in the order the checks run.

    See Also
    --------
    armaxmodal.prepare.prepare : Runs these checks, then detrends, aligns and resamples.
    armaxmodal.QualityWarning : What each check returns.

    Examples
    --------
    >>> import numpy as np
    >>> import armaxmodal as am
    >>> from armaxmodal.prepare import check_quality
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)
    >>> check_quality(ride)  # a clean ride
    []
    >>> twice = am.Recording(ride.fs, ride.base, np.column_stack([ride.response, ride.response[:, 1]]),
    ...                      [*ride.sensors, "chest_copy"])  # the chest exported twice
    >>> [(note.code, note.channels) for note in check_quality(twice)]
    [('duplicate_channel', ('chest_copy', 'chest'))]
    """
    found = duplicate_channels(recording)
    found += delay_and_inversion(recording)
    found += narrowband_input(recording)
    found += clipped_channels(recording)
    found += stuck_channels(recording)
    found += held_samples(recording)
    found += incoherent_outputs(recording)
    found += unit_mismatch(recording)
    return found
