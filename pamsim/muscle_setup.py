"""A muscle ready for a run or a static query: its parameters with the dynamics'
defaults and the user's overrides, and a static model that applies to it.

Scenarios (``[parameters]``, ``[model] static_force``) and the command line
(``--set NAME=VALUE``, ``--model``) share these checks; each passes a ``fail``
callback ``fail(key, value, why, choices=None)`` that raises its own error
naming its own file or option, and ``key`` maps a kind (``"parameter"``,
``"model"``, ``"variant"``) and a name to the key the user wrote.
"""

from __future__ import annotations

from typing import Any, Callable, Mapping

from .muscles import Muscle, load_muscle
from .muscles.schema import KNOWN
from .parameters import ParameterSet, dynamics_parameters, known_parameter
from .static_models import REGISTRY, StaticModelSpec
from .static_models.base import did_you_mean

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
            fail(key("parameter", name), value,
                 "unknown parameter" + (did_you_mean(name, sorted(set(params) | set(KNOWN))) or " (`pamsim params` "
                                        "lists a muscle's parameters)"))
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            fail(key("parameter", name), value, f"must be a number, not {type(value).__name__}")
        (values if name in params else added)[name] = float(value)
    params = params.with_overrides(values, source=source)
    if added:
        entries = dict(params.entries)
        entries.update({k: known_parameter(k, x, source) for k, x in added.items()})
        params = ParameterSet(params.name, params.citation, entries)
    for name, value, why in params.violations():
        fail(key("parameter", name), value, why)
    return params


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


def prepare(muscle: str, model: str | None = None, overrides: Mapping[str, Any] | None = None,
            variant: str | None = None, fail: Fail | None = None, key: Key | None = None):
    """Load ``muscle`` and return ``(muscle, parameters, built static model)`` for static queries.

    The Python face of ``pamsim force`` / ``pamsim static`` / ``pamsim atlas``:
    without ``fail`` every mistake raises :class:`~pamsim.errors.InputError`.
    """
    from .errors import InputError

    def default_fail(k, value, why, choices=None):
        raise InputError(f"{k} = {value!r}: {why}" + (f" (choose from {', '.join(map(str, choices))})"
                                                     if choices and len(choices) < 20 else ""))

    fail = fail or default_fail
    key = key or (lambda kind, name: {"parameter": name, "model": "model", "variant": "variant"}[kind])
    m = load_muscle(muscle)
    params = with_overrides(dynamics_parameters(m.parameters), overrides or {}, fail, key, "override")
    spec = applicable_model(model or m.default_static_force, variant, m, params, fail, key)
    return m, params, spec.build(params, variant)
