"""The fitted muscle as a ``muscle.toml`` file (the format of pamsim's muscle files: top-level
``name``, ``description``, ``citation``, ``default_static_force``, one ``[parameters.NAME]`` table per
parameter with ``value``, ``source`` and ``description``, and an optional ``[data]`` table naming the
measured points relative to the file), and the reading of ``--muscle`` arguments.
"""

from __future__ import annotations

import difflib
import json
import math
from dataclasses import replace
from pathlib import Path
from typing import Mapping

from ..errors import InputError
from ..parameters import PARAMETER_SETS, ParameterSet
from ..scenario import read_toml

_TOP_KEYS = {"name", "description", "citation", "default_static_force", "rated_pressure_gauge_Pa", "parameters",
             "data"}
_PARAM_KEYS = {"value", "source", "description"}
TEMPLATE_SET = "shadow_6x300_acra2012"
"""Parameter set whose names, units and ranges a muscle file's parameters are checked against."""


class MuscleFileError(InputError):
    """A muscle file that cannot be used; names the file, the key and the value."""


def _s(text: str) -> str:
    return json.dumps(text, ensure_ascii=False)  # a JSON string is a valid TOML basic string


def _v(value: float) -> str:
    if not math.isfinite(value):
        raise ValueError(f"cannot write non-finite value {value!r}")
    return repr(float(value))


def muscle_toml(params: ParameterSet, name: str, description: str, citation: str, static_force: str,
                provenance: Mapping[str, object], data_file: str | None = None) -> str:
    """Text of a muscle file holding every parameter of ``params``.

    ``provenance`` (data file, its SHA-256, date, objective, RMS, ...) is written as comment lines at
    the top; the fitted parameters carry it in their ``source`` as well.
    """
    lines = [f"# {k}: {v}" for k, v in provenance.items()]
    lines += [f"name = {_s(name)}", f"description = {_s(description)}", f"citation = {_s(citation)}",
              f"default_static_force = {_s(static_force)}", ""]
    for key, entry in params.entries.items():
        lines += [f"[parameters.{key}]", f"value = {_v(entry.value)}", f"source = {_s(entry.source)}",
                  f"description = {_s(entry.description)}", ""]
    if data_file:
        lines += ["[data]", f"file = {_s(data_file)}", ""]
    return "\n".join(lines)


def load_muscle_parameters(name_or_path: str) -> tuple[ParameterSet, str]:
    """The parameter set named by ``--muscle`` and its static force model.

    A registered parameter set name, or a muscle file path (anything with ``/`` or ending in
    ``.toml``), whose parameters override the template set.  Returns ``(parameters, model)``.
    """
    if "/" not in name_or_path and not name_or_path.endswith(".toml"):
        if name_or_path not in PARAMETER_SETS:
            close = difflib.get_close_matches(name_or_path, list(PARAMETER_SETS), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else f" (choose from {', '.join(PARAMETER_SETS)})"
            raise MuscleFileError(f"--muscle = {name_or_path!r}: unknown muscle{hint}")
        return PARAMETER_SETS[name_or_path], "acra2012_polynomial"
    path = Path(name_or_path)
    spec = read_toml(path, "muscle", MuscleFileError)
    for key in spec:
        if key not in _TOP_KEYS:
            close = difflib.get_close_matches(key, sorted(_TOP_KEYS), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise MuscleFileError(f"{path}: {key} = {spec[key]!r}: unknown key{hint}")
    template = PARAMETER_SETS[TEMPLATE_SET]
    table = spec.get("parameters", {})
    if not isinstance(table, dict):
        raise MuscleFileError(f"{path}: parameters = {table!r}: must be a table of [parameters.NAME] tables")
    values, sources = {}, {}
    for key, entry in table.items():
        if key not in template:
            close = difflib.get_close_matches(key, list(template), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise MuscleFileError(f"{path}: parameters.{key}: unknown parameter{hint}")
        if not isinstance(entry, dict) or "value" not in entry:
            raise MuscleFileError(f"{path}: parameters.{key} = {entry!r}: must be a table with a value")
        for sub in entry:
            if sub not in _PARAM_KEYS:
                raise MuscleFileError(f"{path}: parameters.{key}.{sub} = {entry[sub]!r}: unknown key")
        value = entry["value"]
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise MuscleFileError(f"{path}: parameters.{key}.value = {value!r}: must be a finite number")
        values[key] = float(value)
        sources[key] = str(entry.get("source", f"{path}"))
    params = template.with_overrides(values, source=str(path))
    entries = dict(params.entries)
    for key, src in sources.items():
        entries[key] = replace(entries[key], source=src)
    params = ParameterSet(str(spec.get("name", path.stem)), str(spec.get("citation", "")), entries)
    for key, value, why in params.violations():
        raise MuscleFileError(f"{path}: parameters.{key}.value = {value!r}: {why}")
    model = spec.get("default_static_force", "acra2012_polynomial")
    return params, str(model)
