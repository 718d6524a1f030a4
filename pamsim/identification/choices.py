"""Choices and defaults of the fits, in a module without numpy so that the command line can offer
them without importing the numerical code (``pamsim --help`` stays quick)."""

OBJECTIVES = ("force", "contraction")
LOSSES = ("linear", "soft_l1", "huber", "cauchy", "arctan")
CENSOR_THRESHOLD_M = 0.5e-3
"""Measured contraction at or below which a hung load counts as not lifted (0.5 mm)."""
CV_CHOICES = ("auto", "loo", "kfold", "none")
KNOT_TOLERANCE_PA = 10.0
"""Default largest deviation of the thinned pressure from the measured one: 0.1 mbar, 0.003 % of a
3.6 bar step; the motion it drives differs by about a micrometre from the full trace's
(docs/identification.md).  A noisy measured pressure needs a tolerance near its noise level, or
every sample becomes a knot."""
FD_RELATIVE_STEP = 1e-3
"""Forward-difference step of the dynamic fit's Jacobian, relative to each coefficient (absolute for
coefficients below 1)."""
DYNAMIC_DEFAULT_FREE = ("D1_N_s_per_m", "D2_N_s2_per_m2", "N2_N_per_bar_m2", "N1_N_per_bar_m", "N0_N_per_bar")
"""The paper's eq. (13) coefficients (its Table 4)."""
DYNAMIC_BACKENDS = ("python", "native")
"""Simulators of the dynamic fit (``fit_dynamic(backend=...)``, ``pamsim fit dynamic --backend``); python
is the default."""
