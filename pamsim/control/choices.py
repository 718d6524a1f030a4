"""The linearisation choices, apart from python-control so that the CLI can list them without importing it."""

FRICTION_KINDS = ("dropped", "regularised", "sliding")
"""How a linearisation treats Coulomb friction (see :class:`pamsim.control.system.FrictionTreatment`)."""

VALVE_SLOPES = ("mean", "fill", "vent")
"""Which slope of the valve's flow at command 0 a linearisation takes (see :func:`pamsim.control.linear.linearize`)."""
