"""Effects planted with known size in a recording, so tests build data whose effect the
diagnosis is not told (and ``armaxmodal simulate --effect`` writes such rides)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.signal import lfilter

from ..exceptions import DataError
from ..recording import Recording
from .model import fractional_shift

__all__ = ["inject", "INJECTABLE"]

INJECTABLE = ("input_delay", "offset_drift", "periodic_disturbance", "coloured_noise")


def _channel(rec: Recording, name: str) -> int | None:
    """Column of ``name`` in the response, None for the input."""
    if name == rec.input_name:
        return None
    if name not in rec.sensors:
        raise DataError(f"channel {name!r} is not in this recording ({rec.input_name}, {', '.join(rec.sensors)}).")
    return rec.sensors.index(name)


def inject(recording: Recording, effect: str, channels=None, seed: int = 0, **params) -> Recording:
    """A copy of ``recording`` with one effect planted.

    Parameters
    ----------
    recording : Recording
    effect : str
        ``"input_delay"`` (``samples``, may be fractional: the channel is recorded that late),
        ``"offset_drift"`` (``offset`` in signal units, ``drift_per_s``),
        ``"periodic_disturbance"`` (``freq_hz``; ``amp``, the line's RMS as a fraction of
        each channel's RMS),
        ``"coloured_noise"`` (``level`` as a fraction of RMS; AR(1) ``pole``, or with
        ``freq_hz`` an AR(2) resonance of radius ``pole`` there).
    channels : sequence of str, optional
        Where: default every output (an input delay: the input).
    seed : int
        Random seed of a noise effect.

    Returns
    -------
    Recording
        With ``meta["injected"]`` recording what was planted.
    """
    if effect not in INJECTABLE:
        raise DataError(f"effect: expected one of {INJECTABLE}, got {effect!r}.")
    default = [recording.input_name] if effect == "input_delay" else list(recording.sensors)
    names = list(channels) if channels is not None else default
    base, y = recording.base.copy(), np.array(recording.response, dtype=float)
    rng = np.random.default_rng(seed)
    t = np.arange(recording.n_samples) / recording.fs
    for name in names:
        k = _channel(recording, name)
        x = base if k is None else y[:, k]
        rms = float(np.std(x))
        if effect == "input_delay":
            x[:] = fractional_shift(x, -float(params["samples"]))
        elif effect == "offset_drift":
            x += float(params.get("offset", 0.0)) + float(params.get("drift_per_s", 0.0)) * (t - t.mean())
        elif effect == "periodic_disturbance":
            x += float(params["amp"]) * rms * np.sqrt(2) * np.sin(2 * np.pi * float(params["freq_hz"]) * t + 0.7)
        else:
            w = rng.standard_normal(t.size)
            pole = float(params.get("pole", 0.95))
            if "freq_hz" in params:  # narrowband: an AR(2) resonance of radius ``pole``
                wn = 2 * np.pi * float(params["freq_hz"]) / recording.fs
                v = lfilter([1.0], [1.0, -2 * pole * np.cos(wn), pole**2], w)
            else:
                v = lfilter([1.0], [1.0, -pole], w)
            x += float(params["level"]) * rms * v / np.std(v)
    meta = dict(recording.meta, injected={"effect": effect, "channels": names, **params})
    return replace(recording, base=base, response=y, meta=meta)
