"""Errors raised by the ``orbit`` package.

All are ``ValueError`` subclasses with a one-line message saying what is wrong and with which value,
so that a caller (e.g. the sarcli CLI) can report them to a user without a traceback.
"""


class OrbitError(ValueError):
    """Base class: invalid orbit input or an impossible geometric request."""

    def __init__(self, message: str):
        super().__init__(" ".join(str(message).split()))


class StateVectorError(OrbitError):
    """State vectors are malformed: shapes, non-finite values, duplicate or unsorted times, bad frame."""


class InterpolationRangeError(OrbitError):
    """A requested time lies outside the span covered by the state vectors (plus the allowed margin)."""


class GeometryError(OrbitError):
    """A geometric solve has no solution (e.g. a look that misses the Earth) or did not converge."""
