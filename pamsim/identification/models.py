"""Which static force models a fit can use, and which of their parameters are free by default.

The models come from the static-model library (:mod:`pamsim.static_models`); a fit only needs to
build a model from a parameter mapping and to know the names of the coefficients to vary.
"""

from __future__ import annotations

from typing import Mapping

from .. import static_models
from ..errors import InputError

DEFAULT_FREE: Mapping[str, tuple[str, ...]] = {
    "acra2012_polynomial": ("K1_N_per_bar_m2", "K2_N_per_bar_m", "C1_N_per_bar", "S1_N_per_m2", "S2_N_per_m",
                            "S3_N"),
}
"""Coefficients fitted when ``free`` is not given, where the model's paper fitted them (ACRA 2012 eq. 11).
Any other library model frees its required parameters except the rest length ``L0_m``, which is
measured: for the physical models that is an effective braid radius and rest angle."""
MEASURED = ("L0_m",)


def model_names() -> list[str]:
    """Names of the static force models a fit can use."""
    return static_models.names()


def check_model(name: str, where: str = "--model") -> str:
    """``name`` if it is a library model, else an :class:`InputError` naming the option and the value."""
    try:
        static_models.get(name)
    except InputError as exc:
        raise InputError(f"{where} = {name!r}: {str(exc).split(': ', 1)[-1]}") from None
    return name


def build_static(name: str, params: Mapping[str, float]):
    """The library model ``name`` built from ``params`` (it has ``force_N(x_m, p_gauge_Pa)``)."""
    return static_models.REGISTRY[name].build(params)


def default_free(name: str) -> tuple[str, ...]:
    """The coefficients a fit of ``name`` frees unless told otherwise."""
    if name in DEFAULT_FREE:
        return DEFAULT_FREE[name]
    return tuple(n for n in static_models.REGISTRY[name].parameters if n not in MEASURED)


def missing_inputs(name: str, params: Mapping[str, float]) -> list[str]:
    """Parameters model ``name`` needs that ``params`` does not give."""
    return static_models.REGISTRY[name].missing(params)


def optional_defaults(name: str) -> dict[str, float]:
    """The model's optional coefficients and their defaults (free-able with ``--free``)."""
    return dict(static_models.REGISTRY[name].optional)


def static_parameters(name: str) -> tuple[str, ...]:
    """The parameters model ``name`` is built from."""
    return tuple(static_models.REGISTRY[name].parameters)
