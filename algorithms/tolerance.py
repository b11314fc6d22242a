"""Validation of user tolerances, shared by every algorithm that takes one.

Tolerances are in model units (as in OpenCascade). A tolerance must be a finite
number > 0 (or >= 0 where zero is meaningful); callers that know the model's
size also pass the range it must fall in, so an absurd value (below what double
precision resolves at that size, or larger than the model) is refused with a
message that says why.
"""

from __future__ import annotations

import math

from ..errors import InvalidToleranceError

__all__ = ["check_tolerance"]


def check_tolerance(value: float, name: str = "tol", *, allow_zero: bool = False,
                    low: float = 0.0, high: float = math.inf) -> float:
    """``value`` as a float, or :class:`InvalidToleranceError` saying what is wrong.

    Parameters
    ----------
    value : float
        The tolerance given by the user, in model units.
    name : str
        Its keyword, used in the message.
    allow_zero : bool
        Accept 0 (e.g. "merge only identical points").
    low, high : float
        Range for a model of known size: below ``low`` double precision cannot
        resolve it, above ``high`` it is absurd.
    """
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise InvalidToleranceError(f"{name} must be a positive number, got {value!r}") from None
    if not math.isfinite(value) or value < 0 or (value == 0 and not allow_zero):
        bound = ">= 0" if allow_zero else "> 0"
        raise InvalidToleranceError(f"{name} must be finite and {bound}, got {value!r}")
    if value < low:
        raise InvalidToleranceError(
            f"{name}={value:g} is below what double precision resolves on operands of "
            f"this size (>= {low:.3g} model units)")
    if value > high:
        raise InvalidToleranceError(
            f"{name}={value:g} is absurdly large for operands of this size (<= {high:.3g} "
            "model units)")
    return value
