"""The terms the reports and the command line use, each in a sentence: one source for the
reports' glossary and the docs' glossary page (written from it when the docs build)."""

from __future__ import annotations

import html

__all__ = ["TERMS", "glossary_html"]

#: term -> what it means, in the order a reader meets them
TERMS = {
    "FRF": "Frequency response function: an output's response per unit input at each frequency. For a "
    "base-excited structure, the output's absolute acceleration over the base's (the transmissibility).",
    "EPFRF": "Equivalent point FRF (thesis Eq. 2.20-2.22): the body's motion per unit base acceleration, "
    "-w^2 H(w) M e; the FRF the modes are fitted to and checked against.",
    "H1": "The FRF estimated from the record: the input-output cross-spectrum over the input's "
    "auto-spectrum, averaged over Welch segments (unbiased by noise on the outputs).",
    "coherence": "How much of an output's power at a frequency the input explains linearly, 0 to 1; "
    "below about 0.9 an H1 peak is not a clear one.",
    "H1 random error": "The H1's own scatter from its segments (Bendat & Piersol): what a right model "
    "still misses, given the record's noise.",
    "misfit": "The relative distance between the measured H1 and the one the selected modes synthesise, "
    "over the coherent lines of the input's excited band.",
    "model error": "The misfit beyond the H1's random error: what the modes do not explain. Above the "
    "check's limit the verdict is poor.",
    "LSFD": "Least-squares frequency-domain fit: the modal-model check fits each output's H1 by the "
    "selected poles, residual terms for modes outside the band, and a delay.",
    "ARMAX": "Autoregressive model with moving average and exogenous input: A(q) y = B(q) u + C(q) e, "
    "fitted by the prediction-error method. Its poles are the structure's.",
    "na, nb, nc": "The orders of the ARMAX polynomials A, B and C. The stabilisation diagram sweeps na.",
    "nk": "The input delay of the ARMAX model, in samples at the analysis rate: B's first tap acts nk "
    "samples after the input. Negative: the model uses the input a few samples ahead (a filter's or a "
    "clock's delay between the channels).",
    "stabilisation diagram": "The poles of every swept order, drawn against frequency: a physical mode "
    "stands in a column of poles that agree from order to order.",
    "hold": "How the input moved between its samples, as the modal model assumes it: 'zoh' (held, as a "
    "shaker's controller steps it) or 'bandlimited' (smooth, as a filtered analogue signal). The "
    "likelihood chooses.",
    "estimator": "How a mode's values were made: 'ml-bandlimited' or 'ml-zoh' is the maximum-likelihood "
    "modal model of the record's DFT under that hold; 'armax' is the ARMAX diagram's own.",
    "segments": "The record cut into equal parts, each refitted: their spread shows what the record does "
    "not settle (a mode that moves during the record, a model error).",
    "BIC": "Bayesian information criterion: the fit's likelihood penalised by its parameters; lower is "
    "better, and a difference of 10 is decisive (Kass & Raftery).",
    "MAC": "Modal assurance criterion: the agreement of two mode shapes, 0 (unrelated) to 1 (the same).",
    "95 % interval": "Where the value lies with 95 % probability, given the record: from the fit's "
    "information, widened where the record's segments or the other estimator disagree beyond it.",
    "verdict": "good: the modes explain the measured FRF and the record settles them; uncertain: they "
    "explain it, but the record does not settle them (the notes say why); poor: they do not explain it.",
}


def glossary_html() -> str:
    """The terms as an HTML definition list.

    Returns
    -------
    str
    """
    items = "".join(f"<dt>{html.escape(term)}</dt><dd>{html.escape(text)}</dd>" for term, text in TERMS.items())
    return f"<dl class=glossary>{items}</dl>"
