"""The functions generated from every flat model: their arguments and results, in the order every
backend (the generated Python, the generated C, CasADi) uses."""

FUNCTION_SIGNATURES = {
    "f": (("x", "u", "p", "q"), ("xdot",)),
    "y": (("x", "u", "p", "q"), ("y",)),
    "z": (("x", "u", "p", "q"), ("z", "z_margin")),
    "transition": (("x", "u", "p", "q", "e"), ("x_next", "q_next")),
    "rest_mode": (("x", "u", "p", "q"), ("q_rest",)),
    "x0": (("u", "p"), ("x0", "q0")),
    "settle": (("x", "u", "p", "q", "tol"), ("x_settled",)),
    "jacobian": (("x", "u", "p", "q"), ("A", "B", "C", "D")),
}
"""``{name: (arguments, results)}``: x states, u inputs, p parameters, q modes, e the event indicators
that have crossed (1) or not (0), tol the integrator's relative tolerance."""
