"""The figure of a muscle driven by its length: its force against its contraction (the loops), and the force and
contraction over time.  Plotting only: the run is :func:`pamsim.muscle_alone.run.simulate_length_drive`'s."""

from __future__ import annotations

from matplotlib.figure import Figure

from ..constants import PA_PER_BAR
from ..figure_style import series


def length_drive_figure(result) -> Figure:
    """Two panels: the force against the contraction (each element slip marked on it), and the force and the
    contraction over time (the pressure in the title's range)."""
    fig = Figure(figsize=(7.5, 8.0), layout="constrained")
    ax_loop, ax_t = fig.subplots(2, 1)
    x_mm, F = 1e3 * result.contraction_m, result.force_N
    ax_loop.plot(x_mm, F, label="force", **series(0))
    ax_loop.set_xlabel("contraction [mm]")
    ax_loop.set_ylabel("force the muscle pulls with [N]")
    p = result.p_gauge_Pa / PA_PER_BAR
    pressure = f"{p.min():.3g} bar" if p.min() == p.max() else f"{p.min():.3g} to {p.max():.3g} bar"
    ax_loop.set_title(f"{result.name} ({result.backend}): {pressure}, {len(result.events)} events")
    ax_t.plot(result.t_s, F, label="force [N]", **series(0))
    ax_t.set_xlabel("time [s]")
    ax_t.set_ylabel("force [N]")
    ax_x = ax_t.twinx()
    ax_x.plot(result.t_s, x_mm, label="contraction [mm]", **series(1))
    ax_x.set_ylabel("contraction [mm]")
    lines = ax_t.get_lines() + ax_x.get_lines()
    ax_t.legend(lines, [line.get_label() for line in lines], loc="best", fontsize="small")
    return fig
