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
    """Base class of every error raised on purpose by armaxmodal."""


class DataError(ArmaxModalError, ValueError):
    """A signal, recording or file is unusable as given (NaN, wrong shape, bad column...)."""


class OrderError(ArmaxModalError, ValueError):
    """Model orders are invalid or need more samples than the record has."""


class StructureError(ArmaxModalError, ValueError):
    """Mass, damping or stiffness matrices are not physical, or not of the asked topology."""


class PickError(ArmaxModalError, ValueError):
    """A mode picked by hand is not one the stabilisation diagram offers (outside the band, no
    stable cluster near it, two picks on one cluster)."""


class SettingsError(ArmaxModalError, ValueError):
    """A threshold of the mode selection's settings is outside what it can be (not a positive
    number, a probability above 1, bounds the wrong way round)."""


class ConvergenceWarning(UserWarning):
    """An iterative estimator stopped before its convergence test was met."""
