"""Input validation shared by the numpy functions of :mod:`chebnorm.symbolic`.

Every public numpy function validates its arguments here, once, and then
calls a lambdified kernel that assumes valid input and does not check.

Tolerances (stated once)
------------------------
``UNIT_RTOL = 1e-6``
    A normal ``v`` is accepted as unit when ``abs(|v| - 1) <= UNIT_RTOL``.
    Single-precision normals (relative rounding ``6e-8`` per component)
    pass comfortably; normals of a mesh that were never normalized do not.
``DOT_ATOL = 3 * UNIT_RTOL``
    The dot product of two accepted unit normals lies in
    ``[-(1 + UNIT_RTOL)**2, (1 + UNIT_RTOL)**2]``, i.e. within about
    ``2 * UNIT_RTOL`` of ``[-1, 1]``; cosines given directly are accepted in
    ``[-1 - DOT_ATOL, 1 + DOT_ATOL]`` and then clipped to ``[-1, 1]``.  Two
    normals count as antiparallel when ``1 + N_a.N_b <= DOT_ATOL`` and as
    parallel when ``1 - N_a.N_b <= DOT_ATOL``: below that the dot product is
    indistinguishable from -1 (resp. 1) given the accepted length error.
"""

from __future__ import annotations

import numpy as np

# an implementation module of chebnorm.symbolic: the API is what chebnorm.symbolic exports
__all__: list[str] = []

#: accepted relative deviation ``| |N| - 1 |`` of a vector called unit
UNIT_RTOL = 1e-6
#: accepted absolute slack of a dot product of unit vectors outside ``[-1, 1]``, and the
#: distance from -1 or 1 under which two normals count as antiparallel or parallel
DOT_ATOL = 3 * UNIT_RTOL


def where_text(mask: np.ndarray) -> str:
    """Describe the first ``True`` entry of ``mask`` (for error messages)."""
    if mask.ndim == 0:
        return ""
    index = tuple(int(i) for i in np.argwhere(mask)[0])
    return f" at index {index}"


def real_array(x, name: str, func: str) -> np.ndarray:
    """``x`` as a float array; NaN and infinities are rejected."""
    try:
        arr = np.asarray(x, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{func}: {name} must be real numbers; got {x!r}") from exc
    bad = ~np.isfinite(arr)
    if bad.any():
        raise ValueError(
            f"{func}: {name} must be finite; got {arr[bad].flat[0]!r}{where_text(bad)}"
        )
    return arr


def in_range(
    x, name: str, func: str, lo: float, hi: float, range_text: str
) -> np.ndarray:
    """``x`` as a finite float array with every entry in ``[lo, hi]``."""
    arr = real_array(x, name, func)
    bad = (arr < lo) | (arr > hi)
    if bad.any():
        raise ValueError(
            f"{func}: {name} must lie in {range_text}; "
            f"got {arr[bad].flat[0]!r}{where_text(bad)}"
        )
    return arr


def cosine(x, name: str, func: str) -> np.ndarray:
    """A cosine / dot product of unit vectors, clipped to ``[-1, 1]``."""
    arr = in_range(
        x, name, func, -1.0 - DOT_ATOL, 1.0 + DOT_ATOL,
        f"[-1, 1] (up to DOT_ATOL = {DOT_ATOL:g})",
    )
    return np.clip(arr, -1.0, 1.0)


def vectors(x, name: str, func: str) -> np.ndarray:
    """``x`` as a finite float array of shape ``(..., 3)``."""
    arr = real_array(x, name, func)
    if arr.ndim == 0 or arr.shape[-1] != 3:
        raise ValueError(
            f"{func}: {name} must have shape (..., 3); got shape {arr.shape}"
        )
    return arr


def nonzero_vectors(x, name: str, func: str) -> tuple[np.ndarray, np.ndarray]:
    """``x`` as ``(..., 3)`` vectors none of which is zero; also their lengths."""
    arr = vectors(x, name, func)
    length = np.linalg.norm(arr, axis=-1)
    bad = length == 0.0
    if bad.any():
        raise ValueError(f"{func}: {name} contains a zero vector{where_text(bad)}")
    return arr, length


def unit_vectors(x, name: str, func: str) -> np.ndarray:
    """``x`` as ``(..., 3)`` unit vectors (``abs(|x| - 1) <= UNIT_RTOL``)."""
    arr, length = nonzero_vectors(x, name, func)
    dev = np.abs(length - 1.0)
    bad = dev > UNIT_RTOL
    if bad.any():
        raise ValueError(
            f"{func}: {name} must be unit vectors (| |v| - 1 | <= UNIT_RTOL = "
            f"{UNIT_RTOL:g}); got |v| = {length[bad].flat[0]!r}{where_text(bad)}"
        )
    return arr


def not_antiparallel(c: np.ndarray, names: str, func: str) -> None:
    """Reject ``1 + c <= DOT_ATOL`` (the formula divides by ``1 + c``)."""
    bad = 1.0 + c <= DOT_ATOL
    if bad.any():
        raise ValueError(
            f"{func}: {names} are antiparallel (1 + N_a.N_b = "
            f"{1.0 + c[bad].flat[0]!r}{where_text(bad)}); the formula divides by "
            f"1 + N_a.N_b, which must exceed DOT_ATOL = {DOT_ATOL:g}"
        )


def broadcast(func: str, names: str, *arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    """Broadcast ``arrays`` against each other, or say which shapes clash."""
    try:
        return tuple(np.broadcast_arrays(*arrays))
    except ValueError as exc:
        shapes = ", ".join(str(np.shape(x)) for x in arrays)
        raise ValueError(f"{func}: {names} must broadcast; got shapes {shapes}") from exc


def dot(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Row-wise dot product of ``(..., 3)`` arrays (no checks)."""
    return np.einsum("...i,...i->...", x, y)


def scalar_or_array(x: np.ndarray):
    """A 0-d array as a numpy scalar, any other array unchanged."""
    return x[()] if isinstance(x, np.ndarray) and x.ndim == 0 else x
