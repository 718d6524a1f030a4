"""Plots of results.  Kept apart from the model and the Result class.

The functions take a :class:`pamsim.Result` without importing it: ``Result.plot``
imports this module, and one direction of dependency is enough.
"""

from __future__ import annotations

import itertools
import textwrap

import numpy as np
from matplotlib.figure import Figure

from .atomic import atomic_path
from .constants import PA_PER_BAR
from .figure_style import format_of, save, series

FORCE_STYLE: dict[str, tuple[str, dict]] = {key: (label, series(k, colour)) for k, (key, label, colour) in enumerate((
    ("F_static_N", "static", "C0"),
    ("F_gravity_N", "gravity", "C7"),
    ("F_friction_N", "friction", "C1"),
    ("F_damping_N", "damping", "C2"),
    ("F_stop_N", "stop contact", "C5"),
    ("F_external_N", "external", "C4"),
))}
"""Force key -> (legend label, line style): each force keeps its colour and line style in every figure, whichever
others are drawn."""

HELD_STYLE: dict[int, tuple[str, str]] = {0: ("stuck (friction)", "0.85"), 2: ("on the lower stop", "#f2dcc0"),
                                          3: ("on the upper stop", "#cfe0f0")}
"""Held mode value -> (legend label, shade) of the time the load spends still."""

X_LABEL = "contraction x [mm]\n(positive: shorter, lifts the load)"
F_LABEL = "force on the load [N]\n(positive lifts)"


def shade_held(ax, t_s: np.ndarray, mode: np.ndarray) -> None:
    """Shade the time the load is held: stuck by friction, or resting on a stop."""
    for value, (label, colour) in HELD_STYLE.items():
        held = mode == value
        if held.any():
            ax.fill_between(t_s, 0, 1, where=held, transform=ax.get_xaxis_transform(), color=colour, lw=0,
                            label=label)


MEASURED_STYLE = {"color": "C4", "linewidth": 4.0, "alpha": 0.55, "solid_capstyle": "butt", "marker": "D",
                  "markersize": 5, "markevery": [1], "zorder": 3}
"""A measured end of a test: a thick bar over the window it is the mean of, a diamond at the window's end."""


def measured_labels(measured) -> tuple[str, str]:
    """Legend entries of a measured steady state (:class:`pamsim.paperdata.SteadyState`): its final contraction
    and its stable pressure, each with its value and the window it is the mean of."""
    t0, t1 = measured.window_s
    return (f"measured final contraction {measured.contraction_mm:.2f} mm (mean over {t0:g}-{t1:g} s)",
            f"measured stable pressure {measured.pressure_stable_bar:.3f} bar (mean over {t0:g}-{t1:g} s)")


def measured_note(measured) -> str:
    """The caption's line on a measured steady state: what it is, where it is printed, and that it is all."""
    return (f"measured ({measured.source}): only the final contraction and pressure; the paper draws "
            "this test's trace but does not give it as numbers")


def draw_measured(ax, measured, value: float, label: str) -> None:
    """Mark a measured end value (contraction [mm] or pressure [bar]) on ``ax`` over the window it is the mean of."""
    ax.plot(list(measured.window_s), [value] * 2, label=label, **MEASURED_STYLE)


def result_figure(result: "Result", title: str | None = None, compare: "list[Result] | None" = None,
                  backend: str = "python", measured=None) -> Figure:
    """Contraction, pressure (the muscle's, the supply's and those of the line's components), a PWM or spool
    valve's opening, the gas temperature (a thermal chamber's) and force components against time.

    ``compare`` overlays the contraction of other results (for example the
    constant-friction model).  A ``backend`` other than ``"python"`` is named
    in the title.  ``measured`` (a :class:`pamsim.paperdata.SteadyState`, such as
    :meth:`pamsim.Scenario.measured_steady_state` gives) marks the measured final
    contraction and stable pressure of the test, and the title says that these are
    all the paper gives of it as numbers.
    """
    thermal = "wall_heat_W" in result.signals  # the thermal chamber's: its temperature gets a panel
    loops = LOOP_FORCE in result.signals  # hysteresis elements: their loops get a row of their own
    valve = result.valve_panel()  # a PWM or spool valve's: a small panel under the pressure it drives
    rows, height = (4, 11) if thermal else (3, 9)
    ratios = None
    if valve is not None:
        ratios = [1.0, 1.0, VALVE_PANEL_RATIO] + [1.0] * (rows - 2)
        rows, height = rows + 1, height + VALVE_PANEL_HEIGHT_IN
    fig = Figure(figsize=(9, height + (4 if loops else 0)), constrained_layout=True)
    in_time, loop_row = fig.subfigures(2, 1, height_ratios=[height, 4]) if loops else (fig, None)
    axes = in_time.subplots(rows, 1, sharex=True, height_ratios=ratios)
    _contraction_panel(axes[0], result, compare or [], measured)
    _pressure_panel(axes[1], result, measured)
    if valve is not None:
        _valve_panel(axes[2], result, *valve)
    if thermal:
        _temperature_panel(axes[-2], result)
    _force_panel(axes[-1], result)
    if loops:
        _loop_panels(loop_row.subplots(1, 2), result)
    fig.suptitle(_result_title(result, title, backend, measured))
    return fig


LOOP_FORCE = "hysteresis.F_N"
"""The hysteresis elements' force on the load (Maxwell-slip, Prandtl-Ishlinskii, Bouc-Wen): a run that has it
gets :func:`_loop_panels`."""


def _loop_panels(axes, result: "Result") -> None:
    """The hysteresis loops: the contraction against the pressure, and the elements' force against the
    contraction (with their minor loops, where the input turns inside a cycle)."""
    ax_p, ax_f = axes
    x_mm = result.x_m * 1e3
    ax_p.plot(result.p_gauge_Pa / PA_PER_BAR, x_mm, **series(0, "k"))
    ax_p.set_xlabel("gauge pressure [bar]")
    ax_p.set_ylabel(X_LABEL)
    ax_p.set_title("contraction against pressure", fontsize=9)
    k = len(FORCE_STYLE) + _added_forces(result.signals).index(LOOP_FORCE)  # the force panel's colour for it
    ax_f.plot(x_mm, result.signals[LOOP_FORCE], **series(0, f"C{k % 10}"))
    ax_f.set_xlabel(X_LABEL)
    ax_f.set_ylabel("hysteresis elements' force [N]")
    ax_f.set_title("the elements' force against contraction", fontsize=9)
    for ax in axes:
        ax.grid(alpha=0.3)


def _contraction_panel(ax, result: "Result", compare: "list[Result]", measured) -> None:
    """The contraction over the held time's shading, the compared results' and the measured end, if any."""
    shade_held(ax, result.t_s, result.mode)
    ax.plot(result.t_s, result.x_m * 1e3, **series(0, "k"), label=result.name)
    for k, other in enumerate(compare, start=1):
        ax.plot(other.t_s, other.x_m * 1e3, **series(k, f"C{k - 1}"), label=other.name)
    if measured is not None:
        draw_measured(ax, measured, measured.contraction_mm, measured_labels(measured)[0])
    ax.set_ylabel(X_LABEL)
    ax.legend(loc="lower right", fontsize=8)
    ax.grid(alpha=0.3)


def _pressure_panel(ax, result: "Result", measured) -> None:
    """The muscle's pressure, the supply's where the run has one, those of the components added to the rig
    (:func:`line_pressures`), one line each under its name, and the measured stable pressure, if any."""
    t = result.t_s
    ax.plot(t, result.p_gauge_Pa / PA_PER_BAR, **series(0, "C3"), label="muscle")
    labels = ["muscle"]
    if "supply_gauge_Pa" in result.signals:
        ax.plot(t, result.signals["supply_gauge_Pa"] / PA_PER_BAR, **series(3, "k"), label="supply")
        labels.append("supply")
    line = draw_line_pressures(ax, result, tuple(labels))
    if measured is not None:
        draw_measured(ax, measured, measured.pressure_stable_bar, measured_labels(measured)[1])
    ax.set_ylabel("gauge pressure [bar]")
    ax.legend(loc="lower right", fontsize=8, **({"ncol": 2} if line else {}))
    ax.grid(alpha=0.3)


def draw_line_pressures(ax, result: "Result", taken: tuple[str, ...] = (), **line) -> bool:
    """Each line component's gauge pressure [bar] on ``ax`` (:func:`line_pressures`) with ``line``'s keywords,
    in the styles that differ from series 0 and 3 (the muscle's and the supply's or the feedforward's), under
    its name, or ``NAME (component)`` where the name is one of ``taken`` (the regulator "supply" beside the rig's
    set pressure); whether there was any."""
    pressures = line_pressures(result)
    for (name, p_gauge_Pa), k in zip(pressures.items(), (k for k in itertools.count(1) if k != 3)):
        ax.plot(result.t_s, p_gauge_Pa / PA_PER_BAR, label=f"{name} (component)" if name in taken else name,
                **line, **series(k))
    return bool(pressures)


def line_pressures(result: "Result") -> dict[str, np.ndarray]:
    """Component name -> gauge pressure [Pa] of each component added to the rig that has one (a supply, a
    reservoir, a tube): its ``NAME.p_gauge_Pa``."""
    return {key.partition(".")[0]: np.asarray(values, dtype=float) for key, values in result.signals.items()
            if key.partition(".")[2] == "p_gauge_Pa"}


VALVE_PANEL_RATIO = 0.5
VALVE_PANEL_HEIGHT_IN = 1.8
"""The valve panel's height beside a full panel's, and the inches it adds to the figure."""

VALVE_COLOURS = ("C2", "C9")
"""The valve panel's lines: the inlet (or the spool's command), then the exhaust (or the spool's position)."""


def _valve_panel(ax, result: "Result", ylabel: str, lines: "list[tuple[str, str]]") -> None:
    """The valve's command or opening, or a spool's command and position (``Result.valve_panel``)."""
    for k, (key, label) in enumerate(lines):
        ax.plot(result.t_s, result.signals[key], lw=1, label=label, **series(k, VALVE_COLOURS[k]))
    ax.set_ylabel(ylabel, fontsize=8)
    ax.legend(loc="upper right", fontsize=8, ncol=len(lines))
    ax.grid(alpha=0.3)


def _temperature_panel(ax, result: "Result") -> None:
    """The chamber's gas temperature, and its wall's where the run's model has one."""
    t = result.t_s
    ax.plot(t, result.signals["gas_temperature_K"], **series(0, "C1"), label="gas")
    T_wall = getattr(getattr(getattr(result.model, "source", None), "chamber", None), "T_wall_K", None)
    if T_wall is not None:
        ax.axhline(T_wall, **series(3, "k"), label="wall")
    ax.set_ylabel("chamber temperature [K]")
    ax.legend(loc="upper right", fontsize=8)
    ax.grid(alpha=0.3)


def _force_panel(ax, result: "Result") -> None:
    """The forces on the load: each of the rig's that is ever nonzero in its own style (the friction not for a
    run with hysteresis elements), then those of the components added to the rig."""
    t = result.t_s
    # Hysteresis elements replace the Coulomb friction: its level is then zero, and F_friction_N is zero but
    # where the load sticks, where it holds the micronewtons or less that the integration leaves unbalanced.
    hidden = {"F_friction_N"} if LOOP_FORCE in result.signals else set()
    for key, (label, style) in FORCE_STYLE.items():
        values = result.signals[key]
        if key not in hidden and np.any(values != 0.0):
            ax.plot(t, values, label=label, lw=1, **style)
    for k, key in enumerate(_added_forces(result.signals), start=len(FORCE_STYLE)):
        ax.plot(t, result.signals[key], label=key.split(".", 1)[0], lw=1, **series(k, f"C{k % 10}"))
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_ylabel(F_LABEL)
    ax.set_xlabel("time [s]")
    ax.legend(loc="upper right", fontsize=8, ncol=3)
    ax.grid(alpha=0.3)


def _added_forces(signals) -> list[str]:
    """The forces of components added to the rig: their namespaced ``F_`` outputs (``spring.F_spring_N``)."""
    return [k for k in signals if "." in k and k.split(".", 1)[1].startswith("F_")]


def _result_title(result: "Result", title: str | None, backend: str, measured) -> str:
    """``title``, or the run's name, load and final pressure with the backend if not Python; then the notes on a
    measured end and on the damping's energy, if any."""
    default = (f"{result.name}: {result.mass_kg * result.g_m_s2:.2f} N hanging weight "
               f"({result.mass_kg:.3f} kg), {result.p_gauge_Pa[-1] / PA_PER_BAR:.2f} bar at the end")
    if backend != "python":
        what = "compiled C" if backend == "native" else "the exported FMU"
        default += f"\n{backend} backend ({what})"
    notes = [measured_note(measured)] if measured is not None else []
    notes += [result.damping_energy_note()]
    note = "\n".join(textwrap.fill(n, 90) for n in notes if n)  # the figure is about 90 title characters wide
    return (title or default) + (f"\n{note}" if note else "")


def plot_result(result: "Result", path=None, dpi: int | None = None, **kwargs) -> Figure:
    """:func:`result_figure`, written to ``path`` (atomically) if one is given: PNG, PDF or SVG by the
    path's suffix, at ``dpi`` dots per inch (default 110)."""
    fmt = None if path is None else format_of(path)  # the temporary file's name has no suffix to go by
    fig = result_figure(result, **kwargs)
    if path is not None:
        with atomic_path(path) as tmp:
            save(fig, tmp, fmt, dpi)
    return fig
