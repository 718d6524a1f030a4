"""What one FMU is made of: its variables, its value references, its C core and generated files.

:mod:`pamsim.fmu.generate` writes ``modelDescription.xml`` (FMI 2.0 and 3.0), ``pam_variables.h``
and the documentation from an :class:`FmuSpec`, whichever model it describes: the one-muscle model
under the names of :mod:`pamsim.fmu.variables` (:mod:`pamsim.fmu.muscle_spec`), or any assembly of
components (:mod:`pamsim.fmu.assembly_fmu`); both run the model generated from their components on
the generic core (``pam_gcore.c``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

from .variables import Variable


@dataclass(frozen=True)
class FmuSpec:
    """One FMU's description.

    ``variables`` in table order with their ``value_references``; ``states`` (the continuous states,
    in state-vector order) and ``event_indicators`` name variables of the table; ``inputs`` names the
    inputs in the order signals are listed.  ``sources`` are the hand-written C files it ships, of which
    the ``.c`` ones are compiled but for those ``included`` by another (a unity build), and ``generated`` the files written for it (``{name: text}``) beside
    ``pam_variables.h``, which also gets the lines ``c_extra``.  ``token`` is the instantiation token of
    this build (a hash of everything it is built from), ``fmi_version`` the standard it is for.
    """

    variables: tuple[Variable, ...]
    value_references: Mapping[str, int]
    states: tuple[str, ...]
    event_indicators: tuple[str, ...]
    inputs: tuple[str, ...]
    model_name: str
    identifier: str
    naming: str
    description: str
    sources: tuple[str, ...]
    generated: Mapping[str, str] = field(default_factory=dict)
    c_extra: tuple[str, ...] = ()
    signals: Mapping[str, Any] = field(default_factory=dict)
    experiment: Any = None
    token: str = ""
    fmi_version: int = 2
    included: tuple[str, ...] = ()
    usage: tuple[tuple[str, str], ...] = ()

    @property
    def by_name(self) -> dict[str, Variable]:
        """``{name: variable}``."""
        return {v.name: v for v in self.variables}

    def vr(self, name: str) -> int:
        """The value reference of variable ``name``."""
        return self.value_references[name]

    def compiled(self) -> tuple[str, ...]:
        """The C files the binary is compiled from."""
        return tuple(n for n in self.sources if n.endswith(".c") and n not in self.included)
