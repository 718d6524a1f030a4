"""The fitted muscle as a ``muscle.toml`` file in the format :func:`pamsim.load_muscle` reads
(top-level ``name``, ``description``, ``citation``, ``default_static_force``, one
``[parameters.NAME]`` table per parameter with ``value``, ``source`` and ``description``, the source
muscle's ``[upper_stop]`` table if it has one, and an optional ``[data]`` table naming the measured points
relative to the file), and the reading of ``--muscle`` arguments.
"""

from __future__ import annotations

import json
import math
from typing import Mapping

from ..muscles import DEFAULT_UPPER_STOP_SOURCE, DERIVED, Muscle, load_muscle
from ..parameters import DYNAMICS_DEFAULTS, ParameterSet, dynamics_parameters


def _s(text: str) -> str:
    return json.dumps(text, ensure_ascii=False)  # a JSON string is a valid TOML basic string


def _v(value: float) -> str:
    if not math.isfinite(value):
        raise ValueError(f"cannot write non-finite value {value!r}")
    return repr(float(value))


def muscle_toml(params: ParameterSet, name: str, description: str, citation: str, static_force: str,
                provenance: Mapping[str, object], data_file: str | None = None,
                upper_stop: tuple[str, str] | None = None) -> str:
    """Text of a muscle file holding the parameters of ``params``, and ``upper_stop`` (``(at, source)``)
    as its ``[upper_stop]`` table unless None.

    Dynamics values that are still the defaults every muscle gets (same value and source as
    :data:`pamsim.parameters.DYNAMICS_DEFAULTS`) are left out, as in the shipped files.
    ``provenance`` (data file, its SHA-256, date, objective, RMS, ...) is written as comment lines at
    the top; the fitted parameters carry it in their ``source`` as well.
    """
    lines = [f"# {k}: {v}" for k, v in provenance.items()]
    lines += [f"name = {_s(name)}", f"description = {_s(description)}", f"citation = {_s(citation)}",
              f"default_static_force = {_s(static_force)}", ""]
    for key, entry in params.entries.items():
        if key in DYNAMICS_DEFAULTS and (entry.value, entry.source) == DYNAMICS_DEFAULTS[key]:
            continue
        if entry.source.startswith(DERIVED):  # the reader derives it again; written, it could contradict
            continue
        lines += [f"[parameters.{key}]", f"value = {_v(entry.value)}", f"source = {_s(entry.source)}",
                  f"description = {_s(entry.description)}", ""]
    if upper_stop is not None:
        lines += ["[upper_stop]", f"at = {_s(upper_stop[0])}", f"source = {_s(upper_stop[1])}", ""]
    if data_file:
        lines += ["[data]", f"file = {_s(data_file)}", ""]
    return "\n".join(lines)


def upper_stop_table(muscle: Muscle) -> tuple[str, str] | None:
    """``(at, source)`` of ``muscle``'s ``[upper_stop]`` table, or None if its file names none (it then
    takes the default choice, which a fitted file without the table takes again)."""
    if muscle.upper_stop_source == DEFAULT_UPPER_STOP_SOURCE:
        return None
    return muscle.upper_stop, muscle.upper_stop_source


def load_muscle_parameters(name_or_path: str) -> tuple[ParameterSet, str]:
    """The parameters named by ``--muscle`` (a shipped muscle or a muscle file, completed with the
    dynamics' defaults) and the muscle's own static force model."""
    muscle = load_muscle(name_or_path)
    return dynamics_parameters(muscle.parameters), muscle.default_static_force


def scenario_upper_stop(scenario) -> tuple[str, str] | None:
    """The ``[upper_stop]`` table a muscle fitted with ``scenario`` carries: the scenario's ``[model]
    upper_stop`` if it sets one (the stop the fit simulated with), else its muscle's table (or None)."""
    at = scenario.spec["model"].get("upper_stop")
    if at is not None:
        return at, f"the [model] upper_stop of scenario {scenario.name!r}, with which it was fitted"
    return upper_stop_table(scenario.muscle)


def load_upper_stop(name_or_path: str) -> tuple[str, str] | None:
    """The ``[upper_stop]`` table of the muscle named by ``--muscle`` (:func:`upper_stop_table`)."""
    return upper_stop_table(load_muscle(name_or_path))
