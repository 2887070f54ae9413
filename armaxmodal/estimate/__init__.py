"""ARMAX models by the prediction-error method (thesis Chapter 3).

* :func:`~armaxmodal.fit_armax` -- one model per sensor (the thesis's diagonal A) or all sensors sharing
  the poles, by Levenberg-Marquardt on numba kernels; :class:`~armaxmodal.ArmaxFit` the result.
* :func:`~armaxmodal.choose_orders` -- orders and delay by an information criterion.
* :mod:`.pool` -- the worker threads every sweep runs on.
"""

from armaxmodal.estimate.fit import fit_armax
from armaxmodal.estimate.orders import OrderChoice, choose_orders, default_nb, default_nc, information_criterion
from armaxmodal.estimate.result import ArmaxFit

__all__ = ["ArmaxFit", "OrderChoice", "choose_orders", "default_nb", "default_nc", "fit_armax", "information_criterion"]
