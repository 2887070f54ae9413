"""The one result type every inverse method returns."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from armaxmodal.stats import Z95
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

    See Also
    --------
    armaxmodal.inverse.model_update : The joint update.
    armaxmodal.inverse.evphc : The eigenvalue-problem solution (Chapter 2).
    armaxmodal.inverse.pia : The Pilkey-Inman baseline.

    Examples
    --------
    >>> import armaxmodal as am
    >>> system = am.chapter2_system()
    >>> modes = system.modes()
    >>> solution = am.inner_solve(modes.eigenvalues, modes.shapes, total_mass=system.masses.sum(), names=system.names)
    >>> solution.method, solution.converged
    ('inner_solve', True)
    >>> solution.components.k.round(0).tolist()  # Table 2.1: exact modes give the exact springs
    [74000.0, 28000.0, 120800.0, 2400.0]
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
        """The recovered components, one row each, as a tidy table (the modes are
        ``self.modes.to_frame()``).

        Returns
        -------
        pandas.DataFrame
            For a chain: ``component`` (mass, k, c, k_s, c_s), ``location``, ``value``, ``unit`` and,
            where the method gives standard errors (model updating), ``std`` and ``identified``:
            ``"yes"`` where the 95 % interval ``value +- 1.96 std`` excludes zero, ``"no"`` where it
            reaches zero (the data do not tell the component from nothing), ``"fixed"`` for a value
            the scale or a bound holds (std 0), ``"at zero"`` for one held at its lower bound.
            Without a chain (PIA): the diagonals of M, K and C (``component``, ``location``,
            ``value``).

        Examples
        --------
        >>> import armaxmodal as am
        >>> s = am.chapter2_system()
        >>> m = s.modes()
        >>> sol = am.inner_solve(m.eigenvalues, m.shapes, total_mass=s.masses.sum(), names=s.names)
        >>> table = sol.to_frame()
        >>> list(table.columns)
        ['component', 'location', 'value', 'unit']
        >>> print(f"{table.value.iloc[0]:.3f} kg")
        6.000 kg
        """
        if self.components is None:
            s = self.structure
            rows = [
                (kind, n, matrix[i, i])
                for kind, matrix in (("M", s.M), ("K", s.K), ("C", s.C))
                for i, n in enumerate(s.names)
            ]
            return pd.DataFrame(rows, columns=["component", "location", "value"])
        table = self.components.to_frame()
        if self.std is None:
            return table
        std = self.std.to_frame()["value"].to_numpy()
        value = table["value"].to_numpy()
        identified = np.where(
            std == 0, np.where(value == 0, "at zero", "fixed"), np.where(value - Z95 * std > 0, "yes", "no")
        )
        return table.assign(std=std, identified=identified)
