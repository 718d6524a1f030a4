"""Error types the CLI maps to exit codes: user input -> 2, solver and run failures -> 3."""


class InputError(ValueError):
    """Bad user input (scenario file, CLI argument, parameter); exit code 2.

    The message is one line whatever it quotes: a key or file name typed with
    a newline or another control character shows it escaped (``\\n``).
    """

    def __init__(self, message: str = ""):
        super().__init__("".join(c if c.isprintable() else repr(c)[1:-1] for c in str(message)))


class SolverFailure(RuntimeError):
    """The integrator failed or the event logic exceeded its bounds; exit code 3."""


class RunFailure(RuntimeError):
    """The runs could not all be done (a cluster or its workers lost, runs lost to the executor), so
    nothing is reported from them; exit code 3."""
