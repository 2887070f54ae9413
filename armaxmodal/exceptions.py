"""Typed errors and warnings raised by armaxmodal.

Every error says what was expected, what came, and what to do about it. Errors caused by
what the caller passed subclass :class:`ValueError`, so ``except ValueError`` keeps working.
"""

from __future__ import annotations

__all__ = [
    "ArmaxModalError",
    "DataError",
    "OrderError",
    "StructureError",
    "PickError",
    "SettingsError",
    "ConvergenceWarning",
]


class ArmaxModalError(Exception):
    """Base class of every error raised on purpose by armaxmodal.

    See Also
    --------
    armaxmodal.DataError : Bad input data.
    armaxmodal.OrderError : Orders a record cannot support.

    Examples
    --------
    >>> import armaxmodal as am
    >>> issubclass(am.DataError, am.ArmaxModalError), issubclass(am.OrderError, am.ArmaxModalError)
    (True, True)
    """


class DataError(ArmaxModalError, ValueError):
    """A signal, recording or file is unusable as given (NaN, wrong shape, bad column...).

    See Also
    --------
    armaxmodal.ArmaxModalError : The base of the package's errors.

    Examples
    --------
    >>> import numpy as np
    >>> import armaxmodal as am
    >>> try:
    ...     am.Recording(60.0, np.zeros(100), np.full((100, 1), np.nan), ("head",), "base")
    ... except am.DataError as error:
    ...     print(type(error).__name__, isinstance(error, ValueError))
    DataError True
    """


class OrderError(ArmaxModalError, ValueError):
    """Model orders are invalid or need more samples than the record has.

    See Also
    --------
    armaxmodal.ArmaxModalError : The base of the package's errors.

    Examples
    --------
    >>> import armaxmodal as am
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)
    >>> try:
    ...     am.fit_armax(ride.select(["head"]), 400, 400, 400, 0)
    ... except am.OrderError as error:
    ...     print(type(error).__name__)
    OrderError
    """


class StructureError(ArmaxModalError, ValueError):
    """Mass, damping or stiffness matrices are not physical, or not of the asked topology.

    See Also
    --------
    armaxmodal.Structure : What it guards.

    Examples
    --------
    >>> import armaxmodal as am
    >>> try:
    ...     am.Structure.from_chain([1.0, -2.0], [100.0, 50.0], [1.0, 1.0], [30.0], [0.1], ["a", "b"])
    ... except am.StructureError as error:
    ...     print(type(error).__name__)
    StructureError
    """


class PickError(ArmaxModalError, ValueError):
    """A mode picked by hand is not one the stabilisation diagram offers (outside the band, no
    stable cluster near it, two picks on one cluster).

    See Also
    --------
    armaxmodal.select_modes : Its picks.

    Examples
    --------
    >>> import armaxmodal as am
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)
    >>> diagram = am.stabilisation_diagram(ride, range(4, 13, 2), per_sensor=False)
    >>> try:
    ...     am.select_modes(diagram, picks=[25.0])
    ... except am.PickError as error:
    ...     print(type(error).__name__)
    PickError
    """


class SettingsError(ArmaxModalError, ValueError):
    """A threshold of the mode selection's settings is outside what it can be (not a positive
    number, a probability above 1, bounds the wrong way round).

    See Also
    --------
    armaxmodal.modes.settings.SelectionSettings : The thresholds it guards.

    Examples
    --------
    >>> from armaxmodal.exceptions import SettingsError
    >>> from armaxmodal.modes.settings import CountSettings
    >>> try:
    ...     CountSettings(decisive_bic=-1.0)
    ... except SettingsError as error:
    ...     print(type(error).__name__)
    SettingsError
    """


class ConvergenceWarning(UserWarning):
    """An iterative estimator stopped before its convergence test was met.

    See Also
    --------
    armaxmodal.fit_armax : Warns with it.

    Examples
    --------
    >>> import armaxmodal as am
    >>> issubclass(am.ConvergenceWarning, UserWarning)
    True
    """
