"""Measurements against high-precision references, and the register of the draft's claims.

`accuracy` (the gradients and the β-derivative against mpmath, the U-curve's optimum),
`gradient_methods` (the ways of differentiating a height field or a reader's f(x), one record
each) and `gradient_benchmark` (their run time against their error, and what the papers report),
`seed_errata` (the defects of the draft's code, re-measured), `claims` (the draft's
checkable claims, each decided by a stated rule), and `store` (one measurement per
build, shared by the book's pages); `displaced` (sphere A truly displaced, against the
bumped render) and `inverse` (β fitted to a normal map).  Imports `proofs` and `renderer`, never the book.

Every public function checks its arguments once, at its entry, as `renderer.validate` checks the
renderer's (`_checks` holds the lab's own kinds): a bad value raises one
`renderer.validate.InvalidType` or `renderer.validate.InvalidValue` naming the parameter, the
value and what is accepted (tests/test_lab_validation.py tries every parameter).
"""
