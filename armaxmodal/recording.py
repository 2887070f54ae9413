"""A recording: one base-acceleration input and several body/structure sensors."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from armaxmodal._validate import as_signal_matrix, as_signal_vector, check_amplitude, check_fs, check_not_constant
from armaxmodal.exceptions import DataError
from armaxmodal.spectra import welch_spectra

__all__ = ["Recording"]


@dataclass(frozen=True)
class Recording:
    """Synchronously sampled input and outputs.

    Parameters
    ----------
    fs : float
        Sampling rate, Hz.
    base : (n_samples,) array_like
        The measured input (base acceleration, m/s^2, or a force).
    response : (n_samples, n_sensors) array_like
        The outputs, one column per sensor.
    sensors : sequence of str, optional
        Output names (default ``s1..sk``).
    input_name : str
        Name of the input channel (default ``"base"``).
    subject : str, optional
        Who or what was measured.
    mass_kg : float, optional
        Total mass of the subject, kg (used to scale physical models, Eq. 4.7).
    meta : dict
        Anything else worth keeping (source file, simulation truth, ...).

    See Also
    --------
    armaxmodal.read_recording : Read one from a file.
    armaxmodal.simulate_recording : Simulate one with known truth.

    Examples
    --------
    >>> import numpy as np
    >>> import armaxmodal as am
    >>> t = np.arange(600) / 60.0
    >>> base = np.sin(2 * np.pi * 2.0 * t)
    >>> rec = am.Recording(60.0, base, np.column_stack([2 * base, -base]), ("head", "legs"), "base")
    >>> rec.n_samples, rec.duration, rec.sensors
    (600, 10.0, ('head', 'legs'))
    >>> rec.select(["legs"]).sensors
    ('legs',)
    """

    fs: float
    base: np.ndarray
    response: np.ndarray
    sensors: tuple[str, ...] = ()
    input_name: str = "base"
    subject: str | None = None
    mass_kg: float | None = None
    meta: dict = field(default_factory=dict)
    #: this record's Welch spectra by segment length (:meth:`welch`) and its DFT (key ``"dft"``,
    #: :meth:`dft`): computed once, for every stage
    _spectra: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self):
        if not isinstance(self.meta, dict):
            raise DataError(f"meta: expected a dict of metadata (subject, units, ...), got {type(self.meta).__name__}.")
        fs = check_fs(self.fs)
        base = as_signal_vector(self.base, f"input '{self.input_name}'")
        sensors = tuple(self.sensors) if self.sensors else ()
        n_out = np.shape(self.response)[1] if np.ndim(self.response) == 2 else 1
        if not sensors:
            sensors = tuple(f"s{i + 1}" for i in range(n_out))
        response = as_signal_matrix(self.response, "response", sensors)
        if response.shape[0] != base.size:
            raise DataError(
                f"input has {base.size} samples but the outputs have {response.shape[0]}; "
                "trim the channels to a common length (align them by time stamp first)."
            )
        if len(sensors) != response.shape[1] or len(set(sensors)) != len(sensors):
            raise DataError(f"sensors: expected {response.shape[1]} distinct names, got {list(sensors)}.")
        if self.input_name in sensors:
            raise DataError(f"input '{self.input_name}' is also listed as an output sensor.")
        check_amplitude(base[:, None], "input", (self.input_name,))
        check_amplitude(response, "response", sensors)
        check_not_constant(base, f"input '{self.input_name}'")
        if self.mass_kg is not None and not (np.isfinite(self.mass_kg) and self.mass_kg > 0):
            raise DataError(f"mass_kg: expected a positive mass in kg, got {self.mass_kg!r}.")
        base.setflags(write=False)
        response.setflags(write=False)
        object.__setattr__(self, "fs", fs)
        object.__setattr__(self, "base", base)
        object.__setattr__(self, "response", response)
        object.__setattr__(self, "sensors", sensors)

    @property
    def n_samples(self) -> int:
        return self.base.size

    @property
    def n_sensors(self) -> int:
        return self.response.shape[1]

    @property
    def duration(self) -> float:
        """Record length in seconds."""
        return self.n_samples / self.fs

    @property
    def time(self) -> np.ndarray:
        """Sample times in seconds, starting at 0."""
        return np.arange(self.n_samples) / self.fs

    def channel(self, name: str) -> np.ndarray:
        """One output by name.

        Parameters
        ----------
        name : str
            A sensor's name.

        Returns
        -------
        (n_samples,) ndarray
            That sensor's samples, in the recording's units.
        """
        return self.response[:, self._sensor_index(name)]

    def welch(self, nperseg: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The record's Welch spectra at a segment length, computed at the first call and kept
        with the record (read-only): every stage that holds this record -- the preparation's
        checks, the selection, the modal-model check, the figure -- reads the same ones.

        Parameters
        ----------
        nperseg : int
            Segment length, samples (at most the record's).

        Returns
        -------
        freq_hz : (nperseg // 2 + 1,) ndarray
        puu : (n_freq,) ndarray
            The input's PSD, unit^2/Hz.
        puy : (n_freq, n_sensors) complex ndarray
            Cross-spectral densities ``conj(U) Y``.
        pyy : (n_freq, n_sensors) ndarray
            The outputs' PSDs.
        """
        nperseg = int(nperseg)
        return self._kept(nperseg, lambda: welch_spectra(self.base, self.response, self.fs, nperseg))

    def dft(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The record's DFT, computed at the first call and kept with the record (read-only), as
        :meth:`welch`'s spectra are: the frequency-domain refit and the count fit lines of one cut of
        the record, and each reads them from here.

        Returns
        -------
        freq_hz : (n_samples // 2 + 1,) ndarray
            The DFT's frequencies, Hz.
        base : (n_freq,) complex ndarray
            The input's DFT.
        response : (n_freq, n_sensors) complex ndarray
            The outputs' DFTs.

        Examples
        --------
        >>> import numpy as np
        >>> import armaxmodal as am
        >>> rec = am.Recording(10.0, np.r_[1.0, np.zeros(7)], np.arange(8.0)[:, None], ("a",))  # an impulse in
        >>> freq, base, response = rec.dft()
        >>> freq.tolist(), base.real.tolist(), response.shape, rec.dft()[1] is base  # computed once
        ([0.0, 1.25, 2.5, 3.75, 5.0], [1.0, 1.0, 1.0, 1.0, 1.0], (5, 1), True)
        """
        return self._kept(
            "dft",
            lambda: (
                np.fft.rfftfreq(self.n_samples, 1.0 / self.fs),
                np.fft.rfft(self.base),
                np.fft.rfft(self.response, axis=0),
            ),
        )

    def _kept(self, key, compute) -> tuple[np.ndarray, ...]:
        """``compute()``'s arrays, computed at the first call for ``key`` and kept read-only: every stage
        that holds this record reads the same ones."""
        if key not in self._spectra:
            arrays = compute()
            for array in arrays:
                array.flags.writeable = False
            self._spectra[key] = arrays
        return self._spectra[key]

    def with_meta(self, meta: dict) -> Recording:
        """The same record with other metadata, sharing the spectra computed so far (the samples
        are the same, so are their spectra).

        Parameters
        ----------
        meta : dict
            The new metadata (replaces the old).

        Returns
        -------
        Recording
        """
        out = replace(self, meta=meta)
        out._spectra.update(self._spectra)
        return out

    def select(self, sensors: Sequence[str]) -> Recording:
        """A recording with only the named outputs, in the given order.

        Parameters
        ----------
        sensors : sequence of str
            The outputs to keep, each named once.

        Returns
        -------
        Recording
            The same input, sampling and metadata with only those outputs.
        """
        idx = [self._sensor_index(s) for s in sensors]
        return Recording(
            self.fs,
            self.base,
            self.response[:, idx],
            tuple(sensors),
            self.input_name,
            self.subject,
            self.mass_kg,
            dict(self.meta),
        )

    def split(self, k: int) -> list[Recording]:
        """The record cut into ``k`` disjoint, equal parts in time (the remainder dropped), each
        with the channels and the rate but no metadata (a part's statistics are its own).

        Parameters
        ----------
        k : int
            The number of parts, at least 1.

        Returns
        -------
        list of Recording

        Raises
        ------
        DataError
            ``k`` is not a whole number from 1 to the number of samples.
        """
        if isinstance(k, bool) or not isinstance(k, int | np.integer) or not 1 <= k <= self.n_samples:
            raise DataError(f"k: expected a whole number of parts from 1 to {self.n_samples} (the samples), got {k!r}.")
        n = self.n_samples // k
        return [
            Recording(
                self.fs,
                self.base[i * n : (i + 1) * n],
                self.response[i * n : (i + 1) * n],
                self.sensors,
                self.input_name,
            )
            for i in range(k)
        ]

    def to_frame(self) -> pd.DataFrame:
        """Columns ``time``, the input, then each sensor.

        Returns
        -------
        pandas.DataFrame
            One row per sample.
        """
        data = {"time": self.time, self.input_name: self.base}
        data.update({s: self.response[:, i] for i, s in enumerate(self.sensors)})
        return pd.DataFrame(data)

    def _sensor_index(self, name: str) -> int:
        if name not in self.sensors:
            raise DataError(f"unknown sensor '{name}'; the outputs are {list(self.sensors)}.")
        return self.sensors.index(name)
