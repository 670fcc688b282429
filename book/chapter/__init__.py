"""The book's presentation helpers, imported by its pages (and by a downloaded notebook).

`page` (glue a value, show a figure, show MyST), `figures` (the figure style and the
explanatory diagrams), `layout` (what of a figure collides: the check `page.show`
runs), `theorems` (a theorem's box and the
§6 ledger), `verdicts` (the draft's claims as margin notes where the reader meets
them, and the register), and the book's words for what the lower layers return:
`labels` (a measurement's scene and size), `claim_words` (the claims' sentences and
rules), `errata_words` (the errata's sentences) and `benchmark` (the gradient
methods' table and figure).  The top layer: imports `lab`, `proofs` and `renderer`.
"""
