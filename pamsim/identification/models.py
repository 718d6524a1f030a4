"""Which static force models a fit can use, and which of their parameters are free by default.

The models come from pamsim's static-force registry; a fit only needs to build a model from a
parameter mapping and to know the names of the coefficients that shape it.
"""

from __future__ import annotations

import difflib
from typing import Mapping

from ..elements.static_force import STATIC_FORCE_MODELS
from ..errors import InputError

DEFAULT_FREE: Mapping[str, tuple[str, ...]] = {
    "acra2012_polynomial": ("K1_N_per_bar_m2", "K2_N_per_bar_m", "C1_N_per_bar", "S1_N_per_m2", "S2_N_per_m",
                            "S3_N"),
}
"""Coefficients fitted when ``free`` is not given: the ones the model's paper fitted (ACRA 2012 eq. 11)."""


def model_names() -> list[str]:
    """Names of the static force models a fit can use."""
    return list(STATIC_FORCE_MODELS)


def check_model(name: str, where: str = "--model") -> str:
    """``name`` if it is a known static force model, else an :class:`InputError` with a suggestion."""
    if name not in STATIC_FORCE_MODELS:
        close = difflib.get_close_matches(name, model_names(), n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else f" (choose from {', '.join(model_names())})"
        raise InputError(f"{where} = {name!r}: unknown static force model{hint}")
    return name


def build_static(name: str, params: Mapping[str, float]):
    """The static force element ``name`` built from ``params`` (it has ``force_N(x_m, p_gauge_Pa)``)."""
    return STATIC_FORCE_MODELS[name](params)


def default_free(name: str) -> tuple[str, ...]:
    """The coefficients a fit of ``name`` frees unless told otherwise."""
    if name not in DEFAULT_FREE:
        raise InputError(f"--model = {name!r}: no default free parameters known; name them with --free")
    return DEFAULT_FREE[name]
