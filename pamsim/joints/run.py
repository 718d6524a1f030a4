"""Running muscles on a joint on either backend."""

from __future__ import annotations

from ..errors import InputError
from .fmu import simulate_joint_cs, simulate_joint_me
from .native import simulate_joint_native
from .result import JointResult
from .scenario import JointScenario
from .simulate import simulate_joint_python

BACKENDS = {"python": simulate_joint_python, "native": simulate_joint_native, "fmu-cs": simulate_joint_cs,
            "fmu-me": simulate_joint_me}
"""The backends that run muscles on a joint, by name."""


def simulate_joint(scenario: JointScenario, backend: str = "python") -> JointResult:
    """Integrate ``scenario`` and return its :class:`JointResult`: with ``scipy.integrate.solve_ivp``
    (``backend="python"``), on the generic C engine (``"native"``,
    :func:`pamsim.joints.native.simulate_joint_native`), or through its FMU with fmpy (``"fmu-cs"``,
    ``"fmu-me"``, :func:`pamsim.joints.fmu.simulate_joint_fmu`).

    Raises
    ------
    InputError
        A backend that does not run joints, or an input the native engine cannot carry.
    SolverFailure
        The integrator failed, or the run had more than ``solver.max_events`` events.
    """
    if backend not in BACKENDS:
        raise InputError(f"{scenario.origin}: backend {backend!r}: muscles on a joint run on "
                         f"{' and '.join(BACKENDS)} so far")
    return BACKENDS[backend](scenario)
