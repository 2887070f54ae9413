"""Effects planted with known size in a recording, so tests build data whose effect the
diagnosis is not told (and ``armaxmodal simulate --effect`` writes such rides)."""

from __future__ import annotations

from dataclasses import replace

import numba
import numpy as np
from scipy.signal import lfilter

from armaxmodal.diagnosis.model import fractional_shift, moved
from armaxmodal.exceptions import DataError
from armaxmodal.recording import Recording

__all__ = ["inject", "INJECTABLE", "RIDE_EFFECTS", "add_second_input", "stiffened_ride"]

INJECTABLE = (
    "input_delay",
    "offset_drift",
    "level_shift",
    "gain_change",
    "clock_drift",
    "periodic_disturbance",
    "coloured_noise",
    "clipping",
    "sensor_fault",
    "second_input",
)
#: a clock that runs off by 1 % or more is a wrong sampling rate, not a drift
MAX_RATE_PPM = 1e4
#: Each effect's parameters: required, then optional.
PARAMETERS = {
    "input_delay": (("samples",), ()),
    "offset_drift": ((), ("offset", "drift_per_s")),
    "level_shift": (("time_s", "size"), ()),
    "gain_change": (("time_s", "factor"), ()),
    "clock_drift": (("rate_ppm",), ()),
    "periodic_disturbance": (("freq_hz", "amp"), ()),
    "coloured_noise": (("level",), ("pole", "freq_hz")),
    "clipping": (("fraction",), ()),
    "sensor_fault": ((), ("spikes", "spike_size", "stuck_s")),
    "second_input": (("level",), ()),
}


#: Effects in the structure itself, planted as the ride is simulated (``armaxmodal simulate``), not
#: in a recording: a joint force between the channels given (one channel: to the base), its size
#: ``ratio`` times the linear spring's (or damper's) force at the linear ride's RMS deflection (or
#: velocity); every spring stiffer by the factor ``stiffening`` from ``time_s`` on.
RIDE_EFFECTS = {
    "stiffness_nonlinearity": (("ratio",), ()),
    "damping_nonlinearity": (("ratio",), ()),
    "time_varying": (("time_s", "stiffening"), ()),
}


def check_effect(effect: str, params: dict) -> None:
    """Raise :class:`DataError` unless ``effect`` is injectable (in a recording, or in the structure
    as a ride is simulated: :data:`RIDE_EFFECTS`) with exactly these parameters."""
    if effect not in INJECTABLE and effect not in RIDE_EFFECTS:
        raise DataError(f"effect: expected one of {INJECTABLE + tuple(RIDE_EFFECTS)}, got {effect!r}.")
    required, optional = {**PARAMETERS, **RIDE_EFFECTS}[effect]
    missing = [k for k in required if k not in params]
    unknown = [k for k in params if k not in required + optional]
    if missing or unknown:
        raise DataError(
            f"effect {effect!r}: needs {', '.join(required) or 'no parameter'}"
            f"{' (optional ' + ', '.join(optional) + ')' if optional else ''}; "
            f"missing {missing or 'none'}, unknown {unknown or 'none'}."
        )
    if any(not np.isfinite(float(v)) for v in params.values()):
        raise DataError(f"effect {effect!r}: parameters must be finite numbers, got {params}.")
    if effect == "second_input" and not float(params["level"]) > 0:
        raise DataError(f"effect 'second_input': level must be > 0, got {params['level']}.")
    if effect == "clipping" and not 0 < float(params["fraction"]) <= 1:
        raise DataError(f"effect 'clipping': fraction must be in (0, 1] (1 clips nothing), got {params['fraction']}.")
    if effect == "sensor_fault" and not (
        int(params.get("spikes", 0)) == params.get("spikes", 0) >= 0 <= params.get("stuck_s", 0)
        and params.get("spikes", 0) + params.get("stuck_s", 0) > 0
    ):
        raise DataError(
            f"effect 'sensor_fault': give spikes (a whole number >= 0) and/or stuck_s (seconds >= 0), "
            f"not both zero; got {params}."
        )


def _channel(rec: Recording, name: str) -> int | None:
    """Column of ``name`` in the response, None for the input."""
    if name == rec.input_name:
        return None
    if name not in rec.sensors:
        raise DataError(f"channel {name!r} is not in this recording ({rec.input_name}, {', '.join(rec.sensors)}).")
    return rec.sensors.index(name)


def inject(recording: Recording, effect: str, channels=None, seed: int = 0, structure=None, **params) -> Recording:
    """A copy of ``recording`` with one effect planted.

    Parameters
    ----------
    recording : Recording
    effect : str
        ``"input_delay"`` (``samples``, may be fractional: the channel is recorded that late),
        ``"offset_drift"`` (``offset`` in signal units, ``drift_per_s``),
        ``"level_shift"`` (``time_s``, ``size`` in signal units: the offset steps then),
        ``"gain_change"`` (``time_s``, ``factor``: the channel reads that much more from then on),
        ``"clock_drift"`` (``rate_ppm``: the channel's delay grows by that many microseconds a
        second, from none at the start, as on a recorder synchronised when it started),
        ``"periodic_disturbance"`` (``freq_hz``; ``amp``, the line's RMS as a fraction of
        each channel's RMS),
        ``"coloured_noise"`` (``level`` as a fraction of RMS; AR(1) ``pole``, or with
        ``freq_hz`` an AR(2) resonance of radius ``pole`` there),
        ``"clipping"`` (``fraction``: both rails at this fraction of the channel's largest
        excursion from its median; 1 clips nothing),
        ``"sensor_fault"`` (``spikes`` single-sample glitches of ``spike_size`` (default 8)
        times the channel's RMS, random sign, at random samples; ``stuck_s`` seconds from 40 %
        of the record on which the channel repeats its last value),
        ``"second_input"`` (``level``; see :func:`add_second_input`: needs ``structure``).
    channels : sequence of str, optional
        Where: default every output (an input delay: the input; a second input: the first
        sensor).
    seed : int
        Random seed of a noise effect.
    structure : Structure, optional
        The structure recorded (a second input's force acts on it).

    Returns
    -------
    Recording
        With ``meta["injected"]`` recording what was planted.
    """
    check_effect(effect, params)
    if effect in RIDE_EFFECTS:
        raise DataError(
            f"effect {effect!r} acts in the structure, not on a recorded channel: plant it as the ride is "
            "simulated (armaxmodal simulate --effect, or nonlinear_joint_ride)."
        )
    if effect == "second_input":
        if structure is None:
            raise DataError("effect 'second_input' needs the structure the force acts on: pass structure=.")
        names = list(channels) if channels is not None else [recording.sensors[0]]
        if len(names) != 1:
            raise DataError(f"effect 'second_input': one channel (where the force acts), got {names}.")
        return add_second_input(recording, structure, names[0], float(params["level"]), seed)
    if effect in ("level_shift", "gain_change") and not 0 < float(params["time_s"]) < recording.duration:
        raise DataError(
            f"effect {effect!r}: time_s must lie inside the record (0-{recording.duration:g} s), "
            f"got {params['time_s']}."
        )
    if effect == "gain_change" and not float(params["factor"]) > 0:
        raise DataError(f"effect 'gain_change': factor must be > 0, got {params['factor']}.")
    if effect == "clock_drift" and not abs(float(params["rate_ppm"])) < MAX_RATE_PPM:
        raise DataError(
            f"effect 'clock_drift': rate_ppm must lie within +-{MAX_RATE_PPM:g} (a clock off by more is "
            f"a wrong sampling rate, not a drift), got {params['rate_ppm']}."
        )
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
        elif effect == "clock_drift":
            rate = 1e-6 * float(params["rate_ppm"])
            x[:] = moved(x, -rate * (x.size - 1) / 2, -rate)  # x[t - rate t]: no delay at the start
        elif effect == "level_shift":
            x[t >= float(params["time_s"])] += float(params["size"])
        elif effect == "gain_change":
            x[t >= float(params["time_s"])] *= float(params["factor"])
        elif effect == "sensor_fault":
            at = rng.choice(np.arange(10, t.size - 10), int(params.get("spikes", 0)), replace=False)
            x[at] += float(params.get("spike_size", 8.0)) * rms * rng.choice([-1.0, 1.0], at.size)
            first, held = int(0.4 * t.size), int(round(float(params.get("stuck_s", 0.0)) * recording.fs))
            x[first + 1 : first + 1 + held] = x[first]
        elif effect == "clipping":
            mid = float(np.median(x))
            rail = float(params["fraction"]) * float(np.max(np.abs(x - mid)))
            x[:] = np.clip(x, mid - rail, mid + rail)
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


#: the joint forces :func:`nonlinear_joint_ride` adds, and the effect each is the truth for
JOINT_FORCES = {"cubic": "stiffness_nonlinearity", "friction": "damping_nonlinearity"}
#: dry friction's sign is smoothed over this fraction of the joint's RMS relative velocity
#: (``tanh(v / v0)``): a discontinuous force would need an event-locating integrator, and at 1 %
#: the force differs from Coulomb's only in the 1 % of time the joint sticks
FRICTION_SMOOTHING = 0.01


def cubic_spring_ride(
    structure,
    base: np.ndarray,
    fs: float,
    between: tuple[int, int],
    ratio: float,
    *,
    noise: float = 0.05,
    seed: int = 0,
    oversample: int = 16,
) -> Recording:
    """A ride of ``structure`` with a cubic spring between DOFs ``between``: the truth for
    ``stiffness_nonlinearity`` (:func:`nonlinear_joint_ride` with ``force="cubic"``)."""
    return nonlinear_joint_ride(
        structure, base, fs, between, ratio, force="cubic", noise=noise, seed=seed, oversample=oversample
    )


def nonlinear_joint_ride(
    structure,
    base: np.ndarray,
    fs: float,
    between: tuple[int, int],
    ratio: float,
    *,
    force: str = "cubic",
    noise: float = 0.05,
    seed: int = 0,
    oversample: int = 16,
) -> Recording:
    """A ride of ``structure`` with a nonlinear force added in the joint between DOFs
    ``between = (i, j)`` (``j = -1``: to the base).

    ``force="cubic"`` is a cubic spring ``k3 s^3`` on the deflection ``s = z_i - z_j`` (the truth
    for ``stiffness_nonlinearity``), set so that at the linear ride's RMS deflection it is
    ``ratio`` times the linear spring's force ``|K_ij| s`` there. ``force="friction"`` is dry
    (Coulomb) friction ``F tanh(v / v0)`` on the joint's relative velocity ``v`` (the truth for
    ``damping_nonlinearity``), ``F`` set to ``ratio`` times the linear damper's force
    ``|C_ij| v`` at the linear ride's RMS relative velocity, ``v0`` :data:`FRICTION_SMOOTHING`
    of it. Integrated by classical Runge-Kutta on a grid ``oversample`` times finer than ``fs``
    with the band-limited input interpolated exactly (FFT); relative coordinates
    ``M z'' + C z' + K z + f_nl = -M 1 a``; outputs are absolute accelerations with white noise
    of ``noise`` times their RMS. ``meta["injected"]`` holds the force's size (``k3`` or ``F``).
    """
    from scipy.signal import resample

    from armaxmodal.systems.simulation import add_noise, simulate

    if force not in JOINT_FORCES:
        raise ValueError(f"force must be one of {sorted(JOINT_FORCES)}, not {force!r}")
    i, j = between
    m_inv = 1.0 / np.diag(structure.M)
    quantity = "displacement" if force == "cubic" else "velocity"
    lin = simulate(structure, base, fs, hold="bandlimited", quantity=quantity, frame="relative")
    rel = lin[:, i] - (lin[:, j] if j >= 0 else 0.0)
    rms = float(np.sqrt(np.mean(rel**2)))
    if force == "cubic":
        k_lin = abs(structure.K[i, j]) if j >= 0 else abs(structure.K[i].sum())
        size, scale, kind = ratio * k_lin / rms**2, 1.0, 0
    else:
        c_lin = abs(structure.C[i, j]) if j >= 0 else abs(structure.C[i].sum())
        size, scale, kind = ratio * c_lin * rms, FRICTION_SMOOTHING * rms, 1
    r = int(oversample)
    fine = resample(base, base.size * 2 * r)  # values at every half step
    c, k = np.ascontiguousarray(structure.C, float), np.ascontiguousarray(structure.K, float)
    acc = _rk4_joint(m_inv, c, k, np.ascontiguousarray(fine), 1.0 / (fs * r), i, j, float(size), kind, scale)
    absolute = acc[::r][: base.size] + base[:, None]
    y = add_noise(absolute, noise, np.random.default_rng(seed))
    sized = {"k3": size} if force == "cubic" else {"friction_force": size}
    meta = {"injected": {"effect": JOINT_FORCES[force], "force": force, "between": [i, j], **sized, "ratio": ratio}}
    names = structure.names or tuple(f"dof{k + 1}" for k in range(y.shape[1]))
    return Recording(fs, base.copy(), y, names, meta=meta)


@numba.njit(cache=True)
def _accel(m_inv, c, k, z, v, a_base, i, j, size, kind, scale):
    f = c @ v + k @ z
    if kind == 0:  # a cubic spring on the deflection
        f_nl = size * (z[i] - (z[j] if j >= 0 else 0.0)) ** 3
    else:  # dry friction on the relative velocity, its sign smoothed
        f_nl = size * np.tanh((v[i] - (v[j] if j >= 0 else 0.0)) / scale)
    f[i] += f_nl
    if j >= 0:
        f[j] -= f_nl
    return -m_inv * f - a_base


@numba.njit(cache=True)
def _rk4_joint(m_inv, c, k, fine, h, i, j, size, kind, scale):
    """Relative accelerations at every step of ``h`` (input sampled at half steps); numba
    because the loop is 10^5 small steps."""
    n_dof = m_inv.size
    steps = fine.size // 2
    z, v = np.zeros(n_dof), np.zeros(n_dof)
    out = np.empty((steps, n_dof))
    for t in range(steps):
        a0, a_half, a1 = fine[2 * t], fine[2 * t + 1], fine[(2 * t + 2) % fine.size]
        k1v = _accel(m_inv, c, k, z, v, a0, i, j, size, kind, scale)
        out[t] = k1v
        k1z = v
        k2v = _accel(m_inv, c, k, z + 0.5 * h * k1z, v + 0.5 * h * k1v, a_half, i, j, size, kind, scale)
        k2z = v + 0.5 * h * k1v
        k3v = _accel(m_inv, c, k, z + 0.5 * h * k2z, v + 0.5 * h * k2v, a_half, i, j, size, kind, scale)
        k3z = v + 0.5 * h * k2v
        k4v = _accel(m_inv, c, k, z + h * k3z, v + h * k3v, a1, i, j, size, kind, scale)
        k4z = v + h * k3v
        z = z + h / 6 * (k1z + 2 * k2z + 2 * k3z + k4z)
        v = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
    return out


def stiffened_ride(
    structure,
    base: np.ndarray,
    fs: float,
    time_s: float,
    stiffening: float,
    *,
    noise: float = 0.05,
    seed: int = 0,
    hold: str = "bandlimited",
) -> Recording:
    """A ride of ``structure`` whose every spring is ``stiffening`` times stiffer from ``time_s`` on
    (the truth for ``time_varying``): the stiffer structure's ride to the same input and noise from
    then on, so the state jumps there as in an instant change.

    Parameters
    ----------
    structure : Structure
    base : (n,) ndarray
        Base acceleration.
    fs : float
        Sampling rate, Hz.
    time_s : float
        When the springs stiffen, s from the start (inside the ride).
    stiffening : float
        Factor on every spring (> 0).
    noise, seed, hold
        As :func:`armaxmodal.simulate_recording`.

    Returns
    -------
    Recording
        With ``meta["injected"]`` recording the change.
    """
    from armaxmodal.systems.simulation import simulate_recording
    from armaxmodal.systems.structure import Structure

    if not (0 < time_s < base.size / fs and stiffening > 0):
        raise DataError(
            f"time_varying: time_s inside the ride (0-{base.size / fs:g} s) and stiffening > 0; got "
            f"{time_s}, {stiffening}."
        )
    stiffer = Structure(structure.M, structure.C, structure.K * stiffening, structure.names)
    before, after = (simulate_recording(s, base, fs, noise=noise, seed=seed, hold=hold) for s in (structure, stiffer))
    later = (np.arange(before.n_samples) / fs >= time_s)[:, None]
    meta = {"injected": {"effect": "time_varying", "time_s": time_s, "stiffening": stiffening}}
    return Recording(fs, before.base, np.where(later, after.response, before.response), before.sensors, meta=meta)


def add_second_input(recording: Recording, structure, at: str, level: float, seed: int = 0) -> Recording:
    """``recording`` with a second excitation: a force on the mass of sensor ``at``, recorded
    as an extra column ``"force"`` that nothing declares an input (the truth for
    ``second_input``).

    The force is Gaussian random vibration over the base input's default band with its own
    seed, held between samples (a DAC-driven exciter); its response -- absolute accelerations
    of the structure on a base held still, ``M z'' + C z' + K z = e_at f`` discretised exactly
    for that hold -- is added to every output, scaled so that at ``at`` its RMS is ``level``
    times that channel's RMS before. Superposition makes this the ride under both inputs.
    """
    from scipy.signal import cont2discrete, dlsim

    from armaxmodal.systems.simulation import random_vibration

    k_at = _channel(recording, at)
    if k_at is None:
        raise DataError("effect 'second_input': the force acts on a sensor's mass, not on the input.")
    m, c, k = (np.asarray(x, float) for x in (structure.M, structure.C, structure.K))
    dof = m.shape[0]
    if recording.response.shape[1] != dof:
        raise DataError(
            f"effect 'second_input': the recording has {recording.response.shape[1]} outputs, "
            f"the structure {dof} masses."
        )
    m_inv = np.linalg.inv(m)
    a = np.block([[np.zeros((dof, dof)), np.eye(dof)], [-m_inv @ k, -m_inv @ c]])
    b = np.r_[np.zeros(dof), m_inv[:, k_at]][:, None]
    cc, d = a[dof:], b[dof:]
    n, fs = recording.n_samples, recording.fs
    force = random_vibration(fs, n / fs, band=(0.5, min(28.0, 0.47 * fs)), seed=seed + 7919)[:n]
    ad, bd, cd, dd, _ = cont2discrete((a, b, cc, d), 1.0 / fs, method="zoh")
    _, response, _ = dlsim((ad, bd, cd, dd, 1.0 / fs), force)
    scale = level * float(np.std(recording.response[:, k_at])) / float(np.std(response[:, k_at]))
    y = np.column_stack([recording.response + scale * response, scale * force])
    meta = dict(
        recording.meta,
        injected={"effect": "second_input", "channels": ["force"], "at": at, "level": level, "force_scale": scale},
    )
    return replace(recording, response=y, sensors=(*recording.sensors, "force"), meta=meta)
