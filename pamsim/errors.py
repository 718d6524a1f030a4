"""Error types the CLI maps to exit codes: user input -> 2, solver -> 3."""


class InputError(ValueError):
    """Bad user input (scenario file, CLI argument, parameter); exit code 2."""


class SolverFailure(RuntimeError):
    """The integrator failed or the event logic exceeded its bounds; exit code 3."""
