"""A muscle ready for a run or a static query: its parameters with the dynamics'
defaults and the user's overrides, and a static model that applies to it.

Scenarios (``[parameters]``, ``[model] static_force``) and the command line
(``--set NAME=VALUE``, ``--model``) share these checks.  ``key`` maps a kind
(``"parameter"``, ``"model"``, ``"variant"``) and a name to the key the user
wrote; a ``fail(key, value, why, choices=None)`` callback raises the error,
by default :func:`pamsim.table_checks.option_error` (``KEY = VALUE: WHY``, as
the command line reports it), a scenario's naming its file.
"""

from __future__ import annotations

from typing import Any, Callable, Mapping

from .elements.stops import EndStops
from .errors import InputError
from .muscles import Muscle, load_muscle
from .parameter_schema import KNOWN, ParameterSet, known_parameter
from .parameters import dynamics_parameters
from .static_models import REGISTRY, StaticModelSpec
from .table_checks import did_you_mean, number_problem, option_error

Fail = Callable[..., None]
Key = Callable[[str, str], str]


def with_overrides(params: ParameterSet, overrides: Mapping[str, Any], fail: Fail, key: Key,
                   source: str) -> ParameterSet:
    """``params`` with ``overrides`` applied; a known parameter name the muscle lacks is added.

    Every value is checked for type and range, and the result for consistency
    (:meth:`ParameterSet.violations`).
    """
    values, added = {}, {}
    for name, value in overrides.items():
        if name not in params and name not in KNOWN:
            fail(key("parameter", name), value, "unknown parameter" + _suggest(name, sorted(set(params) | set(KNOWN))))
        why = number_problem(value)
        if why:
            fail(key("parameter", name), value, why)
        (values if name in params else added)[name] = float(value)
    params = params.with_overrides(values, source=source)
    if added:
        entries = dict(params.entries)
        entries.update({k: known_parameter(k, x, source) for k, x in added.items()})
        params = ParameterSet(params.name, params.citation, entries)
    for name, value, why in params.violations():
        fail(key("parameter", name), value, why)
    return params


def model_inputs(muscle: Muscle, params: Mapping[str, float]) -> dict:
    """What a static model is built from: ``params`` and, if the muscle has one, its force-map file."""
    inputs = dict(params)
    if muscle.force_map_file is not None:
        inputs["force_map_file"] = muscle.force_map_file
    return inputs


def _suggest(name: str, names: list[str]) -> str:
    """The names that extend ``name`` by a unit suffix (``valve_C`` -> ``valve_C_m3_per_s_Pa``), else the closest."""
    longer = [n for n in names if n.startswith(name + "_")]
    if longer:
        return f" (did you mean {' or '.join(repr(n) for n in longer[:3])}?)"
    return did_you_mean(name, names) or " (`pamsim params` lists a muscle's parameters)"


def applicable_model(name: str, variant: str | None, muscle: Muscle, params: Mapping[str, float], fail: Fail,
                     key: Key) -> StaticModelSpec:
    """The spec of library model ``name``: known, with every parameter it needs, and the variant known."""
    if name not in REGISTRY:
        fail(key("model", name), name, "unknown static force model (`pamsim models` lists them)", list(REGISTRY))
    spec = REGISTRY[name]
    missing = spec.missing(params)
    if missing:
        fail(key("model", name), name, f"needs parameter(s) {', '.join(missing)}, which muscle {muscle.name!r} "
             "does not give (set them or choose another model)")
    if variant is not None and variant not in spec.variants:
        fail(key("variant", variant), variant, f"not a variant of {name!r}", list(spec.variants))
    return spec


def _defaults(fail: Fail | None, key: Key | None) -> tuple[Fail, Key]:
    return (fail or option_error,
            key or (lambda kind, name: {"parameter": name, "model": "model", "variant": "variant"}[kind]))


def muscle_parameters(muscle: str, overrides: Mapping[str, Any] | None = None, fail: Fail | None = None,
                      key: Key | None = None) -> tuple[Muscle, ParameterSet]:
    """Load ``muscle`` (name or path): ``(muscle, its parameters with the dynamics' defaults and overrides)``."""
    fail, key = _defaults(fail, key)
    m = load_muscle(muscle)
    return m, with_overrides(dynamics_parameters(m.parameters), overrides or {}, fail, key, "override")


def prepare(muscle: str, model: str | None = None, overrides: Mapping[str, Any] | None = None,
            variant: str | None = None, fail: Fail | None = None, key: Key | None = None):
    """Load ``muscle`` and return ``(muscle, parameters, built static model)`` for static queries.

    The Python face of ``pamsim force`` / ``pamsim static``: without ``fail``
    every mistake raises :class:`~pamsim.errors.InputError`.
    """
    fail, key = _defaults(fail, key)
    m, params = muscle_parameters(muscle, overrides, fail, key)
    inputs = model_inputs(m, params)
    why = None if model else m.no_model_reason(inputs)
    if why:
        raise InputError(f"muscle {m.name!r}: {why} (its gaps: `pamsim muscles`; or give them with --set)")
    spec = applicable_model(model or m.default_static_force, variant, m, inputs, fail, key)
    return m, params, spec.build(inputs, variant)


def end_stops(muscle: Muscle, params: Mapping[str, float], model, choice: str | None = None,
              key: str = "upper_stop") -> EndStops:
    """The end stops of static ``model`` on ``muscle`` (with ``params``, as :func:`prepare` returns them):
    the upper stop where ``choice`` (:data:`pamsim.elements.stops.UPPER_STOPS`) puts it, by default the
    muscle file's choice.

    Raises
    ------
    InputError
        When the choice cannot be met (:meth:`pamsim.elements.stops.EndStops.for_model`), naming ``key`` and
        the choice, or the muscle and its own choice.
    """
    try:
        return EndStops.for_model(params, model.domain.x_max_m, choice or muscle.upper_stop)
    except ValueError as exc:
        where = f"{key} {choice}" if choice else f"muscle {muscle.name!r}: its upper stop {muscle.upper_stop!r}"
        raise InputError(f"{where}: {exc}") from None
