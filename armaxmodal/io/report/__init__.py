"""What a run shows a person: figures and the one-record HTML report.

* :mod:`.diagram_plot` -- the stabilisation diagram over the measured FRFs, and a prediction
  against the record.
* :mod:`.shape_plot` -- each mode's shape along the sensor chain.
* :mod:`.selection_report` -- a selection's modes table and its self-contained HTML report.
* :mod:`.html_page` -- the page, table and embedded-figure helpers the reports share.

These read the results' attributes only: the stages below hand them what to draw.
"""
