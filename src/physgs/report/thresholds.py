"""The claims ledger's thresholds, named once: every claim of the catalogue
([`physgs.report.catalogue`][physgs.report.catalogue]) takes its threshold from here, and the
pages quote these names. Never move one to make a claim pass."""

#: |median zeta_hat - zeta| / zeta above this: damping not recovered (below: recovered).
DAMPING_OFF = 0.10
#: gamma ~ omega^p with |p| below this: the decay rate is nearly frequency-independent (a band).
RATE_EXPONENT = 0.5
#: the trained model beats the null by less than this (points): "matches".
NULL_MATCH_PP = 0.5
#: a nearest-bone gap within this fraction of the paper's reproduces it.
GAP_RTOL = 0.25
#: an opponent reaches this fraction of the true-motion ceiling's in-window gain over static.
FIT_BAR = 0.5
#: the output-only analysis' 95% intervals hold the truth on at least this share of its parts.
INTERVAL_COVER = 0.8
#: a 95% interval's median half-width over its value below this: informative. At 1 the interval
#: reaches zero: a damping ratio's cannot tell the mode from an undamped pole (the modal
#: analyst's trust rule, ``physgs.oma.intervals.REL_SIGMA_MAX`` = 1 / 1.96, per part).
INFORMATIVE_HALFWIDTH = 1.0
#: the paper's factor: the untrained null's median omega error over the trained model's.
NULL_FACTOR = 2.5
#: a ratio above this: the one above it is better (null / trained errors).
RATIO_EVEN = 1.0
#: a difference on the claimed side of this: the claimed model is ahead (dB, points, px).
EVEN = 0.0
