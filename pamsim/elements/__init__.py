"""Physical elements of the muscle model, one small module each.

Each element is a frozen dataclass holding its parameters, with pure methods
of state and inputs.  They work on floats (inside the right-hand side) and on
numpy arrays (when the simulator reconstructs the force breakdown of a trace).
"""
