"""Muscles as data: TOML files with every value's unit (from its key) and provenance.

``load_muscle("kothera2009_5a")`` loads a shipped muscle; a name containing
``/`` or ending in ``.toml`` is a path.  Any mistake in a file raises
:class:`MuscleError` with one line ``FILE: KEY = VALUE: why``.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any, Mapping

from ..errors import InputError
from ..parameter_schema import KNOWN, LOCK_DEG, UPPER_STOP_DEFAULT, UPPER_STOPS, Parameter, ParameterSet, unit_of
from ..static_models import REGISTRY, StaticForce
from ..static_models import get as get_model
from ..table_checks import did_you_mean, number_problem, shown


class MuscleError(InputError):
    """A muscle file or name that cannot be used; the message names file, key and value."""


TOP_KEYS = ("name", "description", "citation", "default_static_force", "rated_pressure_gauge_Pa", "gaps",
            "force_map", "parameters", "data", "upper_stop")
ENTRY_KEYS = ("value", "source", "description", "unit")
UPPER_STOP_KEYS = ("at", "source")
DEFAULT_UPPER_STOP_SOURCE = ("pamsim default (the file names none): the jam angle where the muscle gives its "
                             "fibres' width and count, else the end of the static model's domain")
"""Provenance of the upper-stop choice of a muscle file without an ``[upper_stop]`` table."""


@dataclass(frozen=True)
class Muscle:
    """A validated muscle: metadata and its :class:`~pamsim.parameters.ParameterSet`.

    Attributes
    ----------
    name, description, citation : from the file.
    default_static_force : registry name of the model to use when none is chosen.
    parameters : values (SI, unit in the name) with unit, source, description and range.
    origin : the file it was read from.
    gaps : values the source does not give (said, not invented).
    data_file : measured points shipped with the muscle, or None.
    force_map_file : measured F(x, p) table for the ``force_map`` model, or None.
    upper_stop, upper_stop_source : where the upper stop stands (a choice of
        :data:`pamsim.elements.stops.UPPER_STOPS`) and why.
    """

    name: str
    description: str
    citation: str
    default_static_force: str
    parameters: ParameterSet
    origin: Path
    gaps: tuple[str, ...] = ()
    data_file: Path | None = field(default=None)
    force_map_file: Path | None = field(default=None)
    upper_stop: str = UPPER_STOP_DEFAULT
    upper_stop_source: str = DEFAULT_UPPER_STOP_SOURCE

    def model_inputs(self) -> dict:
        """What a static model is built from: the parameter values and, if any, the force-map file."""
        inputs: dict = dict(self.parameters)
        if self.force_map_file is not None:
            inputs["force_map_file"] = self.force_map_file
        return inputs

    def applicable_models(self) -> list[str]:
        """Names of the library models whose required inputs this muscle gives."""
        inputs = self.model_inputs()
        return [name for name, spec in REGISTRY.items() if not spec.missing(inputs)]

    def no_model_reason(self, inputs: Mapping[str, Any] | None = None) -> str | None:
        """Why no library model applies to ``inputs`` (default: the file's own), or None when one does."""
        inputs = self.model_inputs() if inputs is None else inputs
        if any(not spec.missing(inputs) for spec in REGISTRY.values()):
            return None
        lacks = ", ".join(get_model(self.default_static_force).missing(inputs))
        return f"no static model applies: its default model {self.default_static_force!r} needs {lacks}, not given"

    def static_force(self, model: str | None = None, variant: str | None = None,
                     overrides: Mapping[str, float] | None = None) -> StaticForce:
        """Build a library model (default: the muscle's own) for this muscle."""
        params = self.model_inputs()
        params.update(overrides or {})
        return get_model(model or self.default_static_force).build(params, variant)


def shipped_names() -> list[str]:
    """Names of the muscles shipped with pamsim."""
    return list(_shipped_names())


@lru_cache(maxsize=1)
def _shipped_names() -> tuple[str, ...]:
    # The package's files do not change while it runs; listing them costs more than a native run.
    return tuple(sorted(p.name[:-5] for p in resources.files(__name__).iterdir() if p.name.endswith(".toml")))


def load_muscle(name_or_path: str | Path) -> Muscle:
    """Load and validate a shipped muscle (by name) or a muscle file (by path).

    Raises
    ------
    MuscleError
        Unknown name, unreadable file, or any invalid key or value.
    """
    text = str(name_or_path)
    if isinstance(name_or_path, Path) or "/" in text or text.endswith(".toml"):
        path = Path(name_or_path)
        if not path.is_file():
            raise MuscleError(f"{path}: no such muscle file")
    else:
        names = _shipped_names()
        if text not in names:
            raise MuscleError(f"muscle = {text!r}: unknown muscle{did_you_mean(text, names)} "
                              f"(shipped: {', '.join(names)})")
        path = _shipped_path(text)
    try:
        stat = path.stat()
    except OSError as exc:
        raise MuscleError(f"{path}: cannot read: {exc}") from None
    return _load_file(path, stat.st_mtime_ns, stat.st_size)


@lru_cache(maxsize=None)
def _shipped_path(name: str) -> Path:
    return Path(str(resources.files(__name__).joinpath(name + ".toml")))


@lru_cache(maxsize=64)
def _load_file(path: Path, mtime_ns: int, size: int) -> Muscle:
    """A muscle file read and validated once per version (its modification time and size are in the key):
    every scenario built from it (thousands in a sweep) shares the immutable :class:`Muscle`."""
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise MuscleError(f"{path}: invalid TOML: {exc}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise MuscleError(f"{path}: cannot read: {exc}") from None
    return muscle_from_dict(raw, path)


def muscle_from_dict(raw: Mapping[str, Any], origin: str | Path = "<dict>") -> Muscle:
    """Validate the structure of a muscle file (already parsed) and build the :class:`Muscle`."""
    origin = Path(origin)

    def fail(key: str, value: Any, why: str) -> MuscleError:
        return MuscleError(f"{origin}: {_key_value(key, value)}: {why}")

    for key in raw:
        if key not in TOP_KEYS:
            raise fail(key, raw[key], "unknown key" + did_you_mean(key, TOP_KEYS))
    strings = _strings(fail, raw)
    model = strings["default_static_force"]
    gaps = raw.get("gaps", [])
    if not isinstance(gaps, list) or not all(isinstance(g, str) for g in gaps):
        raise fail("gaps", gaps, "must be a list of strings")
    entries = _entries(fail, origin, raw)
    force_map_file = _force_map_file(fail, origin, raw)
    data_file = _data_file(fail, origin, raw)
    params = ParameterSet(strings["name"], strings["citation"], entries)
    return Muscle(strings["name"], strings["description"], strings["citation"], model, params, origin,
                  tuple(gaps), data_file, force_map_file, *_upper_stop(fail, raw.get("upper_stop")))


def _strings(fail, raw: Mapping[str, Any]) -> dict[str, str]:
    """The file's name, description, citation and default static force, each a non-empty string; the model
    one of the library's.

    Raises
    ------
    MuscleError
        (made by ``fail``) The first of them missing or blank, or an unknown model.
    """
    strings = {}
    for key in ("name", "description", "citation", "default_static_force"):
        value = raw.get(key)
        if not isinstance(value, str) or not value.strip():
            raise fail(key, value, "required, a non-empty string")
        strings[key] = value
    model = strings["default_static_force"]
    if model not in REGISTRY:
        raise fail("default_static_force", model, "unknown static model" + did_you_mean(model, REGISTRY))
    return strings


def _entries(fail, origin: Path, raw: Mapping[str, Any]) -> dict[str, Parameter]:
    """The ``[parameters.NAME]`` tables and a top-level rating as :class:`Parameter` s, a radial braid angle
    converted, the bladder wall completed and the geometry checked.

    Raises
    ------
    MuscleError
        A table or value that is wrong, a rating given twice, or geometry that does not hold together.
    """
    tables = raw.get("parameters", {})
    if not isinstance(tables, dict):
        raise fail("parameters", tables, "must be a table of [parameters.NAME] tables")
    entries = {name: _entry(fail, origin, name, table) for name, table in tables.items()}
    if "rated_pressure_gauge_Pa" in raw:
        if "rated_pressure_gauge_Pa" in entries:
            raise fail("rated_pressure_gauge_Pa", raw["rated_pressure_gauge_Pa"],
                       "given both at the top level and under [parameters]")
        entries["rated_pressure_gauge_Pa"] = _entry(
            fail, origin, "rated_pressure_gauge_Pa",
            {"value": raw["rated_pressure_gauge_Pa"], "source": f"{origin.name}: top-level rating (no source given)"})
    _convert_radial_angle(fail, entries)
    _complete_wall(fail, entries)
    _check_geometry(fail, entries)
    return entries


def _force_map_file(fail, origin: Path, raw: Mapping[str, Any]) -> Path | None:
    """The measured force map named by ``force_map`` (a CSV file next to the muscle file), or None.

    Raises
    ------
    MuscleError
        (made by ``fail``) A name that is not a string or not a file next to the muscle file.
    """
    if "force_map" not in raw:
        return None
    fm = raw["force_map"]
    if not isinstance(fm, str) or not (origin.parent / fm).is_file():
        raise fail("force_map", fm, "must name a CSV file next to the muscle file")
    return (origin.parent / fm).resolve()


def _data_file(fail, origin: Path, raw: Mapping[str, Any]) -> Path | None:
    """The measured points named by ``[data] file`` (next to the muscle file), or None.

    Raises
    ------
    MuscleError
        (made by ``fail``) A table other than ``{file = "NAME.csv"}``, or no such file.
    """
    if "data" not in raw:
        return None
    data = raw["data"]
    if not isinstance(data, dict) or set(data) != {"file"} or not isinstance(data["file"], str):
        raise fail("data", data, 'must be a table with one key, file = "NAME.csv"')
    data_file = (origin.parent / data["file"]).resolve()
    if not data_file.is_file():
        raise fail("data.file", data["file"], f"no such file next to the muscle file ({data_file})")
    return data_file


def _upper_stop(fail, table: Any) -> tuple[str, str]:
    """``(choice, source)`` of an ``[upper_stop]`` table (``at``, ``source``), or the default without one."""
    if table is None:
        return UPPER_STOP_DEFAULT, DEFAULT_UPPER_STOP_SOURCE
    if not isinstance(table, dict):
        raise fail("upper_stop", table, 'must be a table: at = "CHOICE", source = "where it comes from"')
    for k in table:
        if k not in UPPER_STOP_KEYS:
            raise fail(f"upper_stop.{k}", table[k], "unknown key" + did_you_mean(k, UPPER_STOP_KEYS))
    at, source = table.get("at"), table.get("source")
    if at not in UPPER_STOPS:
        raise fail("upper_stop.at", at, f"must be one of {', '.join(UPPER_STOPS)}")
    if not isinstance(source, str) or not source.strip():
        raise fail("upper_stop.source", source, 'required: why the stop stands there (or "assumed: <reason>")')
    return at, source


def _entry(fail, origin: Path, name: str, table: Any) -> Parameter:
    """One ``[parameters.NAME]`` table -> :class:`Parameter` with the known unit and bounds."""
    key = f"parameters.{name}"
    _check_entry_table(fail, origin, name, table)
    value = _entry_value(fail, key, table)
    source = table.get("source")
    if not isinstance(source, str) or not source.strip():
        raise fail(f"{key}.source", source, 'required: where the value comes from (paper + table/equation, or "assumed: <reason>")')
    unit = unit_of(name)
    if "unit" in table and table["unit"] != unit:
        raise fail(f"{key}.unit", table["unit"], f"does not match the unit of the name's suffix ({unit!r})")
    known, description = _entry_description(fail, key, name, table)
    param = Parameter(value, unit, source, description, known.lower, known.upper, known.lower_open, known.upper_open)
    why = param.violation(value)
    if why:
        raise fail(key, value, why)
    return param


def _check_entry_table(fail, origin: Path, name: str, table: Any) -> None:
    """A known parameter's name (or ``alpha_radial_deg``), its table a table of known keys.

    Raises
    ------
    MuscleError
        An unknown name (its table not quoted: the name is the mistake), a value that is not a table, or an
        unknown key in it.
    """
    key = f"parameters.{name}"
    if name not in KNOWN and name != "alpha_radial_deg":  # the name is the mistake: its table is not quoted
        raise MuscleError(f"{origin}: {key}: unknown parameter"
                          + did_you_mean(name, list(KNOWN) + ["alpha_radial_deg"]))
    if not isinstance(table, dict):
        raise fail(key, table, "must be a table with value and source")
    for k in table:
        if k not in ENTRY_KEYS:
            raise fail(f"{key}.{k}", table[k], "unknown key" + did_you_mean(k, ENTRY_KEYS))


def _key_value(key: str, value: Any) -> str:
    """``key = value`` as a message shows it, or ``missing key KEY`` for None (TOML has no null: a key the
    file leaves out)."""
    return f"missing key {key}" if value is None else f"{key} = {shown(value)}"


def _entry_value(fail, key: str, table: Mapping[str, Any]) -> float:
    """The entry's ``value``, a finite number (a bool is not one)."""
    if "value" not in table:
        raise fail(f"{key}.value", None, "required, a number")
    value = table["value"]
    why = number_problem(value)
    if why:
        raise fail(f"{key}.value", value, why)
    return float(value)


def _entry_description(fail, key: str, name: str, table: Mapping[str, Any]):
    """``(known parameter, description)``: the file's description, else the known one's.

    A radial-plane braid angle takes the bounds of ``theta0_deg``, which it becomes (both lie in (0, 90) deg).
    """
    description = table.get("description", "")
    if not isinstance(description, str):
        raise fail(f"{key}.description", description, "must be a string")
    if name == "alpha_radial_deg":
        return KNOWN["theta0_deg"], description or "braid angle from the plane normal to the axis (Kothera's convention)"
    return KNOWN[name], description or KNOWN[name].description


def _convert_radial_angle(fail, entries: dict[str, Parameter]) -> None:
    """Turn a radial-plane braid angle into ``theta0_deg = 90 - alpha_radial_deg`` at the edge."""
    if "alpha_radial_deg" not in entries:
        return
    alpha = entries.pop("alpha_radial_deg")
    if "theta0_deg" in entries:
        raise fail("parameters.alpha_radial_deg", alpha.value,
                   "give either theta0_deg (from the axis) or alpha_radial_deg (from the radial plane), not both")
    known = KNOWN["theta0_deg"]
    entries["theta0_deg"] = Parameter(90.0 - alpha.value, "deg", f"{alpha.source}; converted: theta0 = 90 deg - "
                                      f"alpha_radial ({alpha.value:g} deg)", known.description,
                                      known.lower, known.upper, known.lower_open, known.upper_open)


DERIVED = "derived: "
"""Start of the ``source`` of a value computed from others when a muscle is read (never written back)."""
WALL_PAIR = ("ri0_m", "wall_thickness_m")
"""The bladder's inner radius and wall thickness: a muscle gives either, the other is ``r0_m`` minus it."""


def _complete_wall(fail, entries: dict[str, Parameter]) -> None:
    """Derive the wall thickness from the inner radius or the reverse; check them if both are given."""
    r0, ri0, t = entries.get("r0_m"), entries.get("ri0_m"), entries.get("wall_thickness_m")
    if r0 is None:
        return
    if ri0 is not None and t is not None:
        if abs(r0.value - ri0.value - t.value) > 1e-9 * r0.value:
            raise fail("parameters.wall_thickness_m", t.value,
                       f"inconsistent with r0_m - ri0_m = {r0.value - ri0.value:g} m")
    elif ri0 is not None:
        k = KNOWN["wall_thickness_m"]
        entries["wall_thickness_m"] = Parameter(r0.value - ri0.value, "m", f"{DERIVED}r0_m - ri0_m", k.description,
                                                k.lower, k.upper, k.lower_open)
    elif t is not None:
        k = KNOWN["ri0_m"]
        entries["ri0_m"] = Parameter(r0.value - t.value, "m", f"{DERIVED}r0_m - wall_thickness_m", k.description,
                                     k.lower, k.upper, k.lower_open)


def rederive(entries: Mapping[str, Parameter]) -> dict[str, Parameter]:
    """``entries`` with every derived value computed again from the values it depends on (after some
    of those changed, as in a fit).  Independent values are kept as they are."""
    out = {k: p for k, p in entries.items() if not p.source.startswith(DERIVED)}

    def fail(key, value, why):
        return MuscleError(f"{_key_value(key, value)}: {why}")

    _complete_wall(fail, out)
    return {k: out[k] for k in entries if k in out} | {k: p for k, p in out.items() if k not in entries}


def geometry_violation(values: Mapping[str, float]) -> tuple[str, float, str] | None:
    """``(name, value, why)`` of the first inconsistency between geometry values, or None."""
    v = values
    if "r0_m" in v and "wall_thickness_m" in v and not v["r0_m"] > v["wall_thickness_m"]:
        return ("r0_m", v["r0_m"], f"braid radius must exceed the bladder wall thickness ({v['wall_thickness_m']:g} m): "
                "the bladder would have no bore")
    if "theta0_deg" in v and v["theta0_deg"] >= LOCK_DEG:
        return ("theta0_deg", v["theta0_deg"],
                f"at or beyond the braid locking angle {LOCK_DEG:.4f} deg: the muscle would not contract")
    if "fit_x_min_m" in v and "fit_x_max_m" in v and not v["fit_x_min_m"] < v["fit_x_max_m"]:
        return ("fit_x_min_m", v["fit_x_min_m"], f"must be below fit_x_max_m = {v['fit_x_max_m']:g}")
    if "valve_b" in v and "valve_laminar_ratio" in v and not v["valve_b"] < v["valve_laminar_ratio"]:
        return ("valve_b", v["valve_b"], f"must be below valve_laminar_ratio = {v['valve_laminar_ratio']:g}")
    if "L0_m" in v and "r0_m" in v and not v["r0_m"] < v["L0_m"]:
        return ("r0_m", v["r0_m"], f"braid radius must be below the rest length ({v['L0_m']:g} m)")
    return None


def _check_geometry(fail, entries: dict[str, Parameter]) -> None:
    """Consistency checks between geometry values."""
    why = geometry_violation({k: p.value for k, p in entries.items()})
    if why:
        raise fail(f"parameters.{why[0]}", why[1], why[2])


__all__ = ["Muscle", "MuscleError", "load_muscle", "muscle_from_dict", "shipped_names", "rederive",
           "geometry_violation", "DERIVED", "WALL_PAIR"]
