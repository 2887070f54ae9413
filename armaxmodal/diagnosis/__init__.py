"""Close the loop with measured data: find the residual, name the effect the model lacks, add
it, refit and report the error before and after.

* :func:`~armaxmodal.diagnosis.diagnose` -- the loop (:mod:`.loop`);
  :class:`~armaxmodal.diagnosis.Diagnosis` its result and JSON (:mod:`armaxmodal.diagnosis.result`).
* :mod:`.effects` -- the registry: one entry per effect (its test, fix, tier, criterion, keep rule).
* :mod:`.model` -- the ARMAX model plus added effects, fitted and held out on blocked folds.
* :mod:`.evidence`, :mod:`.joint_forces`, :mod:`.delays`, :mod:`.missing_mode` -- the residual
  tests, each a statistic with a corrected p-value.
* :mod:`.spectral` -- Thomson's multitaper harmonic F-test for lines.
* :mod:`.fixes` -- each effect's fix and its fitted parameters.
* :mod:`.acceptance` -- the rule that keeps a fix on held-out data; :mod:`.noise_floor` the floor.
* :mod:`.inject` -- effects planted in simulated recordings, to test all of the above.
"""

from armaxmodal.diagnosis.loop import EFFECTS, Diagnosis, diagnose

__all__ = ["Diagnosis", "EFFECTS", "diagnose"]
