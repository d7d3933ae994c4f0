"""The tolerances of the tests, named in one place.

Where a number comes from decides how closely it must agree:

* ``PRINTED``: numbers both programs print with 15 significant digits
  after the same commands; they differ by round-off only.
* ``STEPS``: progress lines and values after iterations (``g``, ``r``,
  ``u``, ...): round-off is amplified by the line search and the
  constraint projections, and the Evolver's own runs differ this much.
* ``LOOSE``: third-party files and long runs compared stage by stage
  (the corpus), values after many iterations, converged studies.
* ``FD``: analytic gradients and Hessians against central differences
  (step 1e-6: truncation error ~ h², round-off ~ eps/h).
* ``ROUNDOFF``: identities of floating-point arithmetic (a quantity
  computed two ways in pyevolver).
"""
PRINTED = 1e-12
STEPS = 1e-9
LOOSE = 1e-6
FD = 1e-6
ROUNDOFF = 1e-12
