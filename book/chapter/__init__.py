"""The book's presentation helpers, imported by its pages (and by a downloaded notebook).

`page` (glue a value, show a figure, show MyST), `figures` (the figure style, the
explanatory diagrams, the text-overlap check), `theorems` (a theorem's box and the
§6 ledger), `verdicts` (the draft's claims where the reader meets them, and the
register).  The top layer: imports `lab`, `proofs` and `renderer`.
"""
