"""The modal-model check: do the selected modes explain the measured FRF?

Least-squares frequency-domain (LSFD) fit of each output's H1 with the selected poles held
fixed, on the lines of the band where that output's coherence is at least
``H1_COHERENCE`` (Heylen, Lammens & Sas, *Modal Analysis Theory and Testing*, Sec. A.3;
the residual terms as in Peeters et al.'s PolyMAX)::

    H_k(w) = exp(-i w tau_k) [ sum_m r_mk / (iw - l_m) + conj(r_mk) / (iw - conj(l_m))
                               + U_k + L_k / (iw)^2 ]

``r_mk`` complex residues, ``U_k`` the upper residual (modes above the band, and the direct
term of an absolute-acceleration transmissibility, which tends to 1 below the first mode),
``L_k`` the lower residual (modes below the band), ``tau_k`` the output's delay against the
input (searched over +-``FrfSettings.max_delay_samples``). A truncated modal sum without these terms
goes to 0 below the first mode where a base-excited structure's transmissibility is 1, and
a sensor's delay adds a phase no modal sum has: without them a check fails right answers.

The statistic per output is the relative RMS misfit ``|H_fit - H1| / |H1|`` over those
lines, reported beside the H1's own random error in the same norm (Bendat & Piersol,
*Random Data*, Sec. 9.2.4, from the coherence). The part of the misfit the random error
does not account for, ``sqrt(max(e^2 - e_random^2, 0))``, is the *model error*; the modes
explain the record when it is at most ``FrfSettings.model_error_limit`` on every output.

``mode_support`` in :mod:`armaxmodal.modes.frf` gives the evidence :func:`armaxmodal.select_modes`
keeps a mode by: how much this check worsens without it (with a neighbour inside its half-power
band refitted in its place, so that one half of a split peak is not needed when the other
can take the whole peak).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from armaxmodal.io.write import finite_or_none
from armaxmodal.modes.settings import CHECK_RESOLUTION, DEFAULTS, FrfSettings
from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.recording import Recording
from armaxmodal.spectra import CoherentLines, coherent_lines, resolving_nperseg
from armaxmodal.stats import H1_COHERENCE

__all__ = ["ModalCheck", "check_modes", "confirmed_modes", "poles_of", "rss_at"]


@dataclass(frozen=True)
class ModalCheck:
    """The LSFD fit of the measured FRF by the selected modes (see the module notes).

    Attributes
    ----------
    sensors : tuple of str
    error, random_error, model_error : (n_sensors,) ndarray
        Relative RMS misfit per output, the H1's random error in the same norm, and the
        misfit beyond it; NaN for an output without coherent lines.
    delay_s : (n_sensors,) ndarray
        Each output's delay against the input that the fit chose, s.
    n_lines : (n_sensors,) ndarray of int
        Coherent lines of the band each output was checked on.
    nperseg : int
        Welch segment length of the H1, samples.
    bands : tuple of (sensor, lo_hz, hi_hz)
        Where the misfit concentrates (empty when the check passes).
    residues : (n_sensors, n_modes) complex ndarray
        The fitted residues ``r_mk``.
    residual_terms : (n_sensors, 2) complex ndarray
        ``U_k`` and ``L_k``.
    poles : (n_modes,) complex ndarray
        The selected poles, rad/s.
    unconfirmed_hz : tuple of float
        Modes (Hz) with no coherent line of any output near them (``confirmed_modes``):
        the record cannot confirm them, whatever the misfit.
    limit : float
        The largest model error of an output whose modes explain it (``FrfSettings.model_error_limit``).
    checked_hz : tuple of (float, float)
        Per output, the lowest and highest coherent line it was checked on (Hz; NaN where it was
        not checked): outside them the fitted FRF is an extrapolation of its residual terms.

    See Also
    --------
    armaxmodal.modes.check_modes : What makes one.

    Examples
    --------
    >>> import armaxmodal as am
    >>> body, exact = am.supine_human(), am.supine_human().modes()  # exact: 5.83, 8.31, 13.50, 16.25 Hz
    >>> ride = am.simulate_recording(body, am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03, seed=2)
    >>> from armaxmodal.modes import check_modes
    >>> check = check_modes(ride, exact.freq_hz, exact.damping)
    >>> check.passed, check.sensors, check.nperseg, check.residues.shape
    (True, ('head', 'chest', 'pelvis', 'legs'), 256, (4, 4))
    """

    sensors: tuple
    error: np.ndarray
    random_error: np.ndarray
    model_error: np.ndarray
    delay_s: np.ndarray
    n_lines: np.ndarray
    nperseg: int
    bands: tuple
    residues: np.ndarray
    residual_terms: np.ndarray
    poles: np.ndarray
    unconfirmed_hz: tuple = ()
    limit: float = DEFAULTS.frf.model_error_limit
    checked_hz: tuple = ()

    @property
    def passed(self) -> bool:
        """Every checked output's model error within ``limit`` and every mode
        confirmed (False when no output has coherent lines: nothing shows that the modes
        explain the record)."""
        checked = np.isfinite(self.model_error)
        fits = bool(checked.any() and np.all(self.model_error[checked] <= self.limit))
        return fits and not self.unconfirmed_hz

    @property
    def failing(self) -> tuple:
        """The checked outputs whose model error exceeds ``limit``."""
        return tuple(s for s, e in zip(self.sensors, self.model_error, strict=True) if e > self.limit)

    @property
    def overall_error(self) -> float:
        """The largest output's relative misfit (NaN when none was checked)."""
        finite = self.error[np.isfinite(self.error)]
        return float(finite.max()) if finite.size else float("nan")

    def frf(self, freq_hz) -> np.ndarray:
        """The fitted FRF, delays included, at ``freq_hz`` (Hz): ``(n_freq, n_sensors)``.

        Parameters
        ----------
        freq_hz : (n_freq,) array_like
            Frequencies, Hz.

        Returns
        -------
        (n_freq, n_sensors) complex ndarray
            Each sensor's FRF over the input.
        """
        f = np.asarray(freq_hz, dtype=float)
        s = 2j * np.pi * f[:, None]
        with np.errstate(divide="ignore", invalid="ignore"):
            modal = _pole_terms(s, self.poles) @ np.vstack([self.residues.T, np.conj(self.residues.T)])
            upper, lower = self.residual_terms[:, 0], self.residual_terms[:, 1]
            return np.exp(-s * self.delay_s) * (modal + upper + lower / s**2)

    def warnings(self) -> list[QualityWarning]:
        """``modes_do_not_explain_frf`` when the check fails, naming the outputs and bands.

        Returns
        -------
        list of QualityWarning
            What the check found wrong, one warning per code.
        """
        if self.passed:
            return []
        found = []
        if self.unconfirmed_hz:
            where = ", ".join(f"{f:.2f}" for f in self.unconfirmed_hz)
            found.append(
                QualityWarning(
                    "modes_do_not_explain_frf",
                    tuple(self.sensors),
                    f"the record does not confirm the mode(s) at {where} Hz: no output's H1 is coherent "
                    f"({H1_COHERENCE:g}) near them, so the check cannot test them (another "
                    "excitation, several moving supports, or noise dominate there). Treat them as unconfirmed",
                    float(self.unconfirmed_hz[0]),
                    tuple(self.unconfirmed_hz),
                )
            )
        checked = np.isfinite(self.model_error)
        if checked.any() and np.all(self.model_error[checked] <= self.limit):
            return found
        if not self.failing:
            return found + [
                QualityWarning(
                    "modes_do_not_explain_frf",
                    tuple(self.sensors),
                    "no output's H1 is coherent (0.8) on enough lines of the band to check the selected modes against: "
                    "treat them as unconfirmed; a longer record or a broader excitation gives the lines",
                )
            ]
        worst = float(np.nanmax(self.model_error))
        where = "; ".join(f"{s} {lo:.2f}-{hi:.2f} Hz" for s, lo, hi in self.bands) or "spread over the band"
        return found + [
            QualityWarning(
                "modes_do_not_explain_frf",
                self.failing,
                f"the selected modes do not explain the measured FRF of {', '.join(self.failing)}: model error up to "
                f"{100 * worst:.0f} % (limit {100 * self.limit:.0f} %) beyond the H1's random error, misfit "
                f"{'at ' if self.bands else ''}{where}. Treat these modes as unconfirmed: look at the figure, widen "
                "--orders or --band, or run 'armaxmodal diagnose'",
                worst,
            )
        ]

    def to_dict(self) -> dict:
        """The JSON form: per output its misfit, the H1's random error, the model error, the
        delay and the lines; the limit; the bands.

        Returns
        -------
        dict
            The check's misfits, verdict and warnings, strict-JSON-ready.
        """
        return {
            "limit": self.limit,
            "passed": self.passed,
            "nperseg": int(self.nperseg),
            "outputs": [
                {
                    "output": s,
                    "error": finite_or_none(self.error[k]),
                    "h1_random_error": finite_or_none(self.random_error[k]),
                    "model_error": finite_or_none(self.model_error[k]),
                    "delay_s": finite_or_none(self.delay_s[k]),
                    "lines": int(self.n_lines[k]),
                }
                for k, s in enumerate(self.sensors)
            ],
            "bands": [{"output": s, "lo_hz": lo, "hi_hz": hi} for s, lo, hi in self.bands],
            "unconfirmed_hz": [float(f) for f in self.unconfirmed_hz],
        }


def poles_of(freq_hz, damping) -> np.ndarray:
    """Continuous poles ``-xi w + i w sqrt(1 - xi^2)`` (rad/s) of modes in Hz and ratios."""
    wn = 2 * np.pi * np.asarray(freq_hz, dtype=float)
    x = np.asarray(damping, dtype=float)
    return -x * wn + 1j * wn * np.sqrt(np.clip(1 - x**2, 0.0, None))


def _pole_terms(s: np.ndarray, poles: np.ndarray) -> np.ndarray:
    """``[1/(s - l_m) ..., 1/(s - conj l_m) ...]``: (n_freq, 2 n_modes)."""
    return np.hstack([1.0 / (s - poles[None]), 1.0 / (s - np.conj(poles)[None])])


def _basis(freq_hz: np.ndarray, poles: np.ndarray) -> np.ndarray:
    """Real-coefficient basis of the module's model without the delay: columns for Re and Im
    of each residue, of ``U`` and of ``L`` (complex valued, (n_freq, 2 n_modes + 4))."""
    s = 2j * np.pi * freq_hz[:, None]
    terms = _pole_terms(s, poles)
    a, b = terms[:, : poles.size], terms[:, poles.size :]
    one = np.ones_like(s)
    return np.hstack([a + b, 1j * (a - b), one, 1j * one, 1 / s**2, 1j / s**2])


def _coefficients_to_terms(coef: np.ndarray, n_modes: int) -> tuple[np.ndarray, np.ndarray]:
    """Residues and ``(U, L)`` from :func:`_basis`'s real coefficients."""
    residues = coef[:n_modes] + 1j * coef[n_modes : 2 * n_modes]
    rest = coef[2 * n_modes :]
    return residues, np.array([rest[0] + 1j * rest[1], rest[2] + 1j * rest[3]])


def check_nperseg(recording: Recording, freq_hz, damping) -> int:
    """Welch segment length of the check (:data:`~armaxmodal.modes.settings.CHECK_RESOLUTION`)."""
    res = CHECK_RESOLUTION
    return resolving_nperseg(recording, freq_hz, damping, res.lines_per_bandwidth, res.min_segments)


def _fit_delays(
    lines: CoherentLines, basis: np.ndarray, fs: float, search: bool, settings: FrfSettings
) -> tuple[float, np.ndarray, float]:
    """The delay (s) of the grid (or zero without ``search``) whose fit leaves the least
    misfit, its coefficients and residual sum of squares. All delays are solved at once
    through one QR of the basis."""
    q, r = np.linalg.qr(np.vstack([basis.real, basis.imag]))
    top, step = (settings.max_delay_samples if search else 0.0), settings.delay_step_samples
    taus = np.arange(-top, top + step / 2, step) / fs
    shifted = lines.h[:, None] * np.exp(2j * np.pi * lines.freq_hz[:, None] * taus[None])
    y = np.vstack([shifted.real, shifted.imag])
    projected = q.T @ y
    rss = np.sum(y**2, axis=0) - np.sum(projected**2, axis=0)
    best = int(np.argmin(rss))
    coef = np.linalg.solve(r, projected[:, best]) if np.all(np.abs(np.diag(r)) > 0) else np.full(r.shape[0], np.nan)
    return float(taus[best]), coef, float(max(rss[best], 0.0))


def rss_at(lines: CoherentLines, poles: np.ndarray, delay_s: float) -> float:
    """Residual sum of squares of the fit with these poles at a fixed delay."""
    basis = _basis(lines.freq_hz, poles)
    a = np.vstack([basis.real, basis.imag])
    shifted = lines.h * np.exp(2j * np.pi * lines.freq_hz * delay_s)
    y = np.concatenate([shifted.real, shifted.imag])
    coef = np.linalg.lstsq(a, y, rcond=None)[0]
    return float(np.sum((y - a @ coef) ** 2))


def check_modes(
    recording: Recording, freq_hz, damping, band=None, *, fit_delay: bool = True, settings: FrfSettings = DEFAULTS.frf
) -> ModalCheck:
    """Fit the measured FRF with the modes' poles fixed (see the module notes).

    Parameters
    ----------
    recording : Recording
        The record the modes were identified from (as fitted: prepared).
    freq_hz, damping : (n_modes,) array_like
        Undamped natural frequencies (Hz) and damping ratios of the selected modes.
    band : (lo, hi), optional
        Band checked, Hz (default: the input's excited band).
    fit_delay : bool
        Fit each output's delay (a nuisance parameter of the check: near a lightly damped
        peak it also absorbs the H1's bias, so it is no measurement of the sensor's delay;
        the ``sensor_delay`` check is). False fits none.
    settings : FrfSettings
        The delays searched, the model-error limit, the lines that confirm a mode.

    Returns
    -------
    ModalCheck

    See Also
    --------
    armaxmodal.modes.ModalCheck : What it returns.
    armaxmodal.select_modes : Runs it on the modes it selects.

    Examples
    --------
    Each sensor's misfit with the four modes, and with the 5.83 Hz mode left out:

    >>> import armaxmodal as am
    >>> body, exact = am.supine_human(), am.supine_human().modes()  # exact: 5.83, 8.31, 13.50, 16.25 Hz
    >>> ride = am.simulate_recording(body, am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03, seed=2)
    >>> from armaxmodal.modes import check_modes
    >>> check_modes(ride, exact.freq_hz, exact.damping).error.round(1), check_modes(ride, exact.freq_hz[1:],
    ...     exact.damping[1:]).error.round(1)
    (array([0., 0., 0., 0.]), array([0. , 0.1, 0.1, 0.3]))
    """
    freq_hz, damping = np.asarray(freq_hz, dtype=float), np.asarray(damping, dtype=float)
    nperseg = check_nperseg(recording, freq_hz, damping)
    poles = poles_of(freq_hz, damping)
    k_out = len(recording.sensors)
    error, rand, delay = (np.full(k_out, np.nan) for _ in range(3))
    residues = np.full((k_out, poles.size), np.nan + 0j)
    terms = np.full((k_out, 2), np.nan + 0j)
    all_lines = coherent_lines(recording, nperseg, band)
    n_params = 2 * poles.size + 5
    for k, lines in enumerate(all_lines):
        if lines.freq_hz.size < n_params:
            continue  # too few coherent lines to say anything of this output
        delay[k], coef, rss = _fit_delays(lines, _basis(lines.freq_hz, poles), recording.fs, fit_delay, settings)
        residues[k], terms[k] = _coefficients_to_terms(coef, poles.size)
        norm = float(np.sum(np.abs(lines.h) ** 2))
        error[k] = np.sqrt(rss / norm)
        rand[k] = np.sqrt(np.sum(lines.sigma**2) / norm)
    model = np.sqrt(np.clip(error**2 - rand**2, 0.0, None))
    checked_hz = tuple(
        (float(ln.freq_hz[0]), float(ln.freq_hz[-1])) if np.isfinite(error[k]) else (np.nan, np.nan)
        for k, ln in enumerate(all_lines)
    )
    seen = confirmed_modes(all_lines, freq_hz, damping, recording.fs / nperseg, settings.feature_lines)
    check = ModalCheck(
        tuple(recording.sensors),
        error,
        rand,
        model,
        delay,
        np.array([ln.freq_hz.size for ln in all_lines]),
        nperseg,
        (),
        residues,
        terms,
        poles,
        tuple(float(f) for f, ok in zip(freq_hz, seen, strict=True) if not ok),
        settings.model_error_limit,
        checked_hz,
    )
    if check.passed:
        return check
    return ModalCheck(**{**check.__dict__, "bands": _misfit_bands(check, all_lines, settings.feature_lines)})


def confirmed_modes(
    all_lines: list[CoherentLines], freq_hz, damping, line_hz: float, confirm_lines: int = DEFAULTS.frf.feature_lines
) -> np.ndarray:
    """Per mode: does some output have a coherent line (:func:`~armaxmodal.spectra.coherent_lines`) within
    ``|f - f_m| <= xi_m f_m + confirm_lines`` lines? A mode where no H1 is coherent is
    one the record cannot confirm: the check's fit never sees it. (The lines next to a sharp
    peak lose coherence to the H1's own bias: right modes on the measured records have their
    nearest coherent line up to 3.7 lines or 4.7 ``xi f`` away; a bridge's 4.13 and 4.17 Hz
    modes inside a band of coherence below 0.8, 9 lines.)"""
    f, x = np.asarray(freq_hz, dtype=float), np.asarray(damping, dtype=float)
    lines = np.concatenate([ln.freq_hz for ln in all_lines]) if all_lines else np.zeros(0)
    reach = np.abs(x) * f + confirm_lines * line_hz
    return np.array([bool(np.any(np.abs(lines - fm) <= r)) for fm, r in zip(f, reach, strict=True)], dtype=bool)


def _misfit_bands(check: ModalCheck, all_lines: list[CoherentLines], min_lines: int) -> tuple:
    """Runs of at least ``min_lines`` lines (gaps of up to two lines bridged) of a
    failing output where the misfit exceeds half the H1 and three times its random error:
    ``(sensor, lo_hz, hi_hz)``, the three with the most misfit."""
    found = []
    for k, lines in enumerate(all_lines):
        if not check.model_error[k] > check.limit:
            continue
        res = np.abs(check.frf(lines.freq_hz)[:, k] - lines.h)
        bad = np.flatnonzero((res > 0.5 * np.abs(lines.h)) & (res > 3 * lines.sigma))
        if bad.size == 0:
            continue
        runs = np.split(bad, np.flatnonzero(np.diff(bad) > 3) + 1)
        for run in runs:
            if run.size >= min_lines:
                energy = float(np.sum(res[run[0] : run[-1] + 1] ** 2))
                found.append((energy, check.sensors[k], float(lines.freq_hz[run[0]]), float(lines.freq_hz[run[-1]])))
    return tuple(item[1:] for item in sorted(found, reverse=True)[:3])
