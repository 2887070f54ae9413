"""The one result type every inverse method returns."""

from __future__ import annotations

from dataclasses import dataclass, field

import pandas as pd

from armaxmodal.systems.structure import ChainComponents, ExactModes, Structure


@dataclass(frozen=True)
class InverseSolution:
    """Physical model recovered from modal data.

    Attributes
    ----------
    structure : Structure
        M (kg), C (N s/m), K (N/m).
    components : ChainComponents or None
        The chain's springs and dampers (None for methods that return full matrices that
        are not a chain, such as PIA).
    modes : ExactModes
        Modes of the recovered model.
    misfits : dict
        Per data block, the misfit at the solution (what each method minimised or reports).
    method : str
    iterations : int
    time_s : float
    converged : bool
    flags : list of str
        Conditions the user must know about (non-convergence, over-damped modes, bounds
        active, not identifiable...).
    std : ChainComponents or None
        Standard errors of the chain components from the stated noise levels (Gauss-Newton
        covariance at the solution; model updating only). A component held at a bound, or
        fixed by the scale, has 0.
    """

    structure: Structure
    components: ChainComponents | None
    modes: ExactModes
    misfits: dict
    method: str
    iterations: int = 0
    time_s: float = 0.0
    converged: bool = True
    flags: list = field(default_factory=list)
    std: ChainComponents | None = None

    def to_frame(self) -> pd.DataFrame:
        """Chain components (or matrix diagonals) and the recovered modes, one row each.

        Returns
        -------
        pandas.DataFrame
            One row per mass, spring and damper (with its standard error where known), then one
            per recovered mode; ``method`` names the solver.
        """
        if self.components is not None:
            comp = self.components.to_frame()
            if self.std is not None:
                comp.insert(3, "std", self.std.to_frame()["value"].to_numpy())
        else:
            s = self.structure
            rows = [("M", n, s.M[i, i]) for i, n in enumerate(s.names)]
            rows += [("K", n, s.K[i, i]) for i, n in enumerate(s.names)]
            rows += [("C", n, s.C[i, i]) for i, n in enumerate(s.names)]
            comp = pd.DataFrame(rows, columns=["component", "location", "value"])
        modes = self.modes.to_frame().assign(component="mode")
        return pd.concat([comp.assign(method=self.method), modes.assign(method=self.method)], ignore_index=True)
