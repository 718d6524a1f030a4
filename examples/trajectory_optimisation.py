"""
Trajectory optimisation of the valve command
============================================

Single-shooting trajectory optimisation of the valve command on pamsim's CasADi model.

Moves the 22.74 N load of ``scenarios/closed_loop_position.toml`` from rest at 20 mm (the chamber
at the holding pressure) to 40 mm: 40 valve commands held for 10 ms each, in [0, 1] (the load only
rises, so the valve only fills or closes), chosen by IPOPT to minimise the squared distance to 40 mm
over the move and the speed at its end.  The
optimiser sees the load sliding up (``CasadiModel.rhs("slip_up")``, RK4); the command it finds is
then run open loop on pamsim's hybrid model, with stick/slip and all, for the answer.  It writes the
command and the response to ``trajectory_optimisation.png``::

    cd examples && python trajectory_optimisation.py
"""

from __future__ import annotations

from pathlib import Path

import casadi as ca
import numpy as np

import pamsim
from pamsim.control.operating_point import holding_pressure_Pa
from pamsim.export import casadi_model
from pamsim.simulator import simulate_model

# The examples run from their folder (the documentation build runs them there too).
SCENARIO = Path("..") / "scenarios" / "closed_loop_position.toml"
N, DT_S, SUBSTEPS = 40, 0.01, 4
X0_M, TARGET_M, HOLD_S = 0.020, 0.040, 0.6


class HeldCommand:
    """A command held constant over intervals of ``dt_s`` (its breakpoints are the switches)."""

    def __init__(self, values, dt_s):
        self.values, self.dt_s = np.asarray(values, dtype=float), dt_s
        self.breakpoints = tuple(dt_s * k for k in range(1, len(self.values)))

    def __call__(self, t):
        k = np.clip(np.floor(np.asarray(t) / self.dt_s).astype(int), 0, len(self.values) - 1)
        return float(self.values[k]) if np.ndim(t) == 0 else self.values[k]


def optimise():
    scenario = pamsim.load_scenario(SCENARIO)
    model = scenario.build_model()
    supply_Pa = scenario.final_pressure_gauge_Pa
    p_hold = holding_pressure_Pa(model, X0_M, model.load.weight_N, supply_Pa)
    cm = casadi_model(scenario, initial_contraction_m=X0_M, initial_pressure_gauge_Pa=p_hold)
    f = cm.rhs("slip_up")

    def step(x, u):  # RK4 over one interval, in SUBSTEPS
        h = DT_S / SUBSTEPS
        for _ in range(SUBSTEPS):
            k1 = f(x, u)
            k2 = f(x + h / 2 * k1, u)
            k3 = f(x + h / 2 * k2, u)
            k4 = f(x + h * k3, u)
            x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        return x

    command = ca.MX.sym("command", N)
    x = ca.MX(cm.x0)
    cost = 0
    for k in range(N):
        x = step(x, ca.vertcat(command[k], supply_Pa, 0.0))
        cost += ((x[0] - TARGET_M) / 1e-3) ** 2 * DT_S + 1e-3 * command[k] ** 2
    cost += (x[1] / 1e-2) ** 2  # arrive at rest
    solver = ca.nlpsol("shooting", "ipopt", {"x": command, "f": cost},
                       {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes", "ipopt.max_iter": 200,
                        "ipopt.tol": 1e-6, "ipopt.acceptable_tol": 1e-3, "ipopt.acceptable_iter": 5})
    # Not from u = 0: the valve opens as |u|, whose derivative there is 0, a stationary point.
    sol = solver(x0=np.full(N, 0.5), lbx=0.0, ubx=1.0)
    u_opt = np.array(sol["x"]).ravel()

    # The command on the hybrid model, held at its last value afterwards.
    source = model.source.__class__(model.source.valve, model.source.chamber, model.source.supply_gauge_Pa,
                                    HeldCommand(u_opt, DT_S), model.source.T_supply_K, model.source.p_atm_Pa)
    hybrid = model.__class__(**{**model.__dict__, "source": source})
    result = simulate_model(hybrid, N * DT_S + HOLD_S, scenario.solver, x0_m=X0_M, p0_gauge_Pa=p_hold,
                            name="trajectory_optimisation")
    return solver.stats(), u_opt, result


def figure(u_opt, result):
    """The command IPOPT chose, and the contraction it gives on the hybrid model."""
    from matplotlib.figure import Figure

    from pamsim.figure_style import series

    fig = Figure(figsize=(7, 5), constrained_layout=True)
    ax_u, ax_x = fig.subplots(2, 1, sharex=True)
    t_u = np.append(DT_S * np.arange(N), result.t_s[-1])  # held at its last value after the move
    ax_u.step(t_u, np.append(u_opt, u_opt[-1]), where="post", **series(0))
    ax_u.set_ylabel("valve command [-]")
    ax_x.plot(result.t_s, 1e3 * result.x_m, label="hybrid model", **series(0))
    ax_x.axhline(1e3 * TARGET_M, label="target", **series(1, colour="0.4"))
    ax_x.set_xlabel("time [s]")
    ax_x.set_ylabel("contraction [mm]")
    ax_x.legend()
    return fig


def main():
    stats, u_opt, result = optimise()
    t_move = N * DT_S
    after = result.t_s >= t_move
    print(f"IPOPT: {stats['return_status']} after {stats['iter_count']} iterations")
    print(f"command: {np.count_nonzero(u_opt > 0.99)} of {N} intervals fully open, "
          f"{np.count_nonzero(u_opt < 0.01)} closed")
    print(f"hybrid model at {t_move:.2f} s: {1e3 * np.interp(t_move, result.t_s, result.x_m):.2f} mm; "
          f"final ({result.t_s[-1]:.2f} s): {1e3 * result.x_m[-1]:.2f} mm, mode {result.final_mode.label}; "
          f"after the move within {1e3 * np.max(np.abs(result.x_m[after] - TARGET_M)):.2f} mm of 40 mm")
    figure(u_opt, result).savefig("trajectory_optimisation.png", dpi=110)
    return result


if __name__ == "__main__":
    main()
