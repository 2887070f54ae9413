"""Close the loop with measured data: find the residual, name the effect the model lacks, add
it, refit and report the error before and after.

* :func:`diagnose` -- the loop (:mod:`.loop`); :class:`Diagnosis` its result and JSON.
* :mod:`.model` -- the ARMAX model plus added effects, fitted and held out on blocked folds.
* :mod:`.evidence` -- the residual tests, each a statistic with a corrected p-value.
* :mod:`.spectral` -- Thomson's multitaper harmonic F-test for lines.
* :mod:`.fixes` -- each effect's fix and its fitted parameters.
* :mod:`.inject` -- effects planted in simulated recordings, to test all of the above.
"""

from armaxmodal.diagnosis.loop import EFFECTS, TESTED_EFFECTS, Diagnosis, diagnose

__all__ = ["Diagnosis", "EFFECTS", "TESTED_EFFECTS", "diagnose"]
