"""What a test of the residual reports: ``Finding`` (its own module, so each family of
tests can build one without importing the others)."""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["Finding"]


@dataclass(frozen=True)
class Finding:
    """One effect the residual points to.

    Attributes
    ----------
    effect : str
        From :data:`armaxmodal.diagnosis.EFFECTS`.
    channels : tuple of str
    statistic : str
        Name of the test statistic.
    value : float
        Its value.
    p : float
        p-value corrected for sensors x tests.
    parameters : dict
        What the test measured (delay in ms, line frequency and amplitude...).
    """

    effect: str
    channels: tuple[str, ...]
    statistic: str
    value: float
    p: float
    parameters: dict = field(default_factory=dict)
    #: What the fix needs beyond the parameters (a nonlinear term's regressor block).
    payload: object = field(default=None, compare=False, repr=False)

    def evidence(self) -> dict:
        return {"statistic": self.statistic, "value": float(self.value), "p": float(self.p)}
