"""Hardware design objects that re-prove themselves, as coefficient tables do.

A design object (:class:`~chebnorm.hw.horner.HornerDesign`,
:class:`~chebnorm.hw.piecewise.PiecewiseDesign`,
:class:`~chebnorm.hw.plain_table.PlainTableDesign`,
:class:`~chebnorm.hw.multipartite.MultipartiteDesign`,
:class:`~chebnorm.hw.exponent.ExponentDesign`, and a
:class:`~chebnorm.hw.pipeline.PipelinedTable` through its base) states a
bound and claims (faithful, correctly rounded, the function it evaluates)
that its printers copy into HDL banners. A design changed after it was
built (``dataclasses.replace``, ``object.__setattr__``, built by hand)
would print them unchecked; so every design verifies itself:

* on construction (``__post_init__``): its bound is re-proved from its own
  integers (the exhaustive certificate recomputed, or the datapath re-sized
  and its interval bound recomputed from its table, itself re-verified) and
  every claim re-checked; a ValueError names the field that is wrong;
* before it prints (:func:`verify_design`, called by every HDL printer): a
  design whose fields changed since (``object.__setattr__``) is proved
  again.

The proof of a content is cached (:func:`check`), keyed on a digest of every
field (:func:`digest`), so an unchanged design is proved once; a design's
own builder, which has just certified what it returns, seals it
(:func:`seal`) instead of proving it twice, and builds its drafts inside
:func:`drafting` (a draft's placeholder fields are not a design's claims).

>>> from chebnorm.hw.plain_table import design_plain_table
>>> import dataclasses
>>> d = design_plain_table("1/sqrt(1+3*x)", ("0", "1"), 4, 4)
>>> dataclasses.replace(d, expression="exp(x)")
Traceback (most recent call last):
...
ValueError: values: the entries of a plain table of exp(x) on [0, 1) are the nearest codes of f; 15 of 16 entries differ (first: code 1 holds 15, nearest 17)
"""

from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import hashlib
from collections import OrderedDict
from fractions import Fraction

import numpy as np

from .design_base import Design

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []

#: digests of the design contents proved (or sealed by their builder), most recent last
_PROVED: "OrderedDict[str, None]" = OrderedDict()
#: how many proved contents are remembered
MAX_PROVED = 512
_DRAFT: contextvars.ContextVar[bool] = contextvars.ContextVar("chebnorm_hw_draft", default=False)


@contextlib.contextmanager
def drafting():
    """Build design drafts inside the block: their construction checks nothing.

    A builder's intermediate objects hold placeholder fields; the builder
    seals what it returns (:func:`seal`), and anything else is proved when it
    is constructed outside the block or printed.

    Yields
    ------
    None
        The block runs with design construction unchecked; the previous
        state is restored on exit, also on an exception.

    Examples
    --------
    >>> import dataclasses
    >>> from chebnorm.hw.plain_table import design_plain_table
    >>> d = design_plain_table("x", ("0", "1"), 3, 3)
    >>> with drafting():   # a test of a bench's own defense: left unchecked
    ...     bad = dataclasses.replace(d, values=(0,) * 8)
    >>> bad.values[:2]
    (0, 0)
    """
    token = _DRAFT.set(True)
    try:
        yield
    finally:
        _DRAFT.reset(token)


def _canonical(value):
    """A hashable, type-tagged picture of ``value`` (fields nested in full)."""
    if hasattr(value, "to_json") and callable(value.to_json) and not isinstance(value, type):
        try:
            return ("json", type(value).__name__, value.to_json())
        except (TypeError, ValueError, AttributeError, RecursionError):
            return ("opaque", id(value))
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return (type(value).__name__,) + tuple(
            (f.name, _canonical(getattr(value, f.name, None))) for f in dataclasses.fields(value))
    if isinstance(value, bool) or value is None:
        return value
    if isinstance(value, (int, np.integer)):
        return ("i", int(value))
    if isinstance(value, (float, np.floating)):
        return ("f", float(value).hex())
    if isinstance(value, Fraction):
        return ("q", value.numerator, value.denominator)
    if isinstance(value, str):
        return ("s", value)
    if isinstance(value, np.ndarray):
        return ("a", str(value.dtype), value.shape, value.tobytes())
    if isinstance(value, (tuple, list)):
        if value and all(type(v) is int for v in value):
            return ("ints", np.asarray(value, dtype=object).tobytes()
                    if any(abs(v) >= 2 ** 62 for v in value)
                    else np.asarray(value, dtype=np.int64).tobytes())
        return (type(value).__name__,) + tuple(_canonical(v) for v in value)
    if isinstance(value, dict):
        return ("d",) + tuple(sorted((repr(k), _canonical(v)) for k, v in value.items()))
    if isinstance(value, Design):   # a design that is not a dataclass (a PipelinedTable)
        return (type(value).__name__, _canonical(value.state()))
    return ("opaque", type(value).__name__, id(value))


def digest(design) -> str:
    """A digest of every field of ``design`` (nested designs and tables in full).

    Parameters
    ----------
    design : object
        A hardware design (a dataclass).

    Returns
    -------
    str
        The SHA-256 of the design's type and fields, in hex.

    Examples
    --------
    >>> import dataclasses
    >>> from chebnorm.hw.plain_table import design_plain_table
    >>> d = design_plain_table("x", ("0", "1"), 3, 3)
    >>> digest(d) == digest(dataclasses.replace(d)), len(digest(d))
    (True, 64)
    """
    return hashlib.sha256(repr((type(design).__name__, _canonical(design))).encode()).hexdigest()


def _record(key: str) -> None:
    _PROVED[key] = None
    _PROVED.move_to_end(key)
    while len(_PROVED) > MAX_PROVED:
        _PROVED.popitem(last=False)


def seal(design):
    """Record ``design``'s present content as proved (its builder's own result).

    Parameters
    ----------
    design : object
        A design its builder has just certified.

    Returns
    -------
    object
        ``design`` itself.

    Examples
    --------
    >>> from chebnorm.hw.plain_table import design_plain_table
    >>> d = design_plain_table("x", ("0", "1"), 3, 3)
    >>> seal(d) is d
    True
    """
    _record(digest(design))
    return design


def check(design, prove):
    """Prove ``design`` with ``prove(design)`` unless this content was proved
    already (or the design is a draft being built, :func:`drafting`).

    Parameters
    ----------
    design : object
        The design.
    prove : callable
        ``prove(design)`` re-proves the bound and the claims, or raises ValueError.

    Returns
    -------
    object
        ``design`` itself.

    Raises
    ------
    ValueError
        From ``prove``: naming the field that does not hold.

    Examples
    --------
    >>> from chebnorm.hw.plain_table import design_plain_table
    >>> d = design_plain_table("x", ("0", "1"), 3, 3)
    >>> calls = []
    >>> check(d, calls.append) is d, calls   # sealed by its builder: not proved twice
    (True, [])
    """
    if _DRAFT.get():
        return design
    key = digest(design)
    if key in _PROVED:
        _PROVED.move_to_end(key)
        return design
    prove(design)
    _record(key)
    return design


def verify_design(design):
    """Re-prove ``design`` if its fields changed since it was proved (its own
    :meth:`~chebnorm.hw.design_base.Design.verify`); anything that is not a
    :class:`~chebnorm.hw.design_base.Design` is returned as it is.

    Parameters
    ----------
    design : object
        A hardware design about to be printed.

    Returns
    -------
    object
        ``design`` itself.

    Raises
    ------
    ValueError
        The design's bound or a claim does not hold for its integers.

    Examples
    --------
    >>> from chebnorm.hw.plain_table import design_plain_table
    >>> d = design_plain_table("x", ("0", "1"), 3, 3)
    >>> object.__setattr__(d, "unproved", 2)
    >>> verify_design(d)
    Traceback (most recent call last):
    ...
    ValueError: unproved: stated 2; accepted: 0 (the roundings that cannot be proved)
    """
    if isinstance(design, Design):
        design.verify()
    return design


def check_certificate(cert, proved: dict, codes: int, what: str) -> None:
    """Refuse an exhaustive certificate that its recomputation ``proved``
    (:meth:`~chebnorm.hw.exhaustive.Reference.error_bounds`) does not support.

    Parameters
    ----------
    cert : ExhaustiveCheck
        The stated certificate.
    proved : dict
        The recomputed bounds: ``upper``, ``lower``, ``at``, ``codes``.
    codes : int
        The number of input codes (``2**in_bits``).
    what : str
        The design, for the message.

    Raises
    ------
    ValueError
        The certificate's ``upper`` is below the recomputed upper bound, its
        ``lower`` above the recomputed lower bound, or its code count or code
        wrong.

    Examples
    --------
    >>> from chebnorm.hw.exhaustive import ExhaustiveCheck
    >>> proved = {"upper": 0.25, "lower": 0.2, "at": 3, "codes": 8}
    >>> check_certificate(ExhaustiveCheck(0.3, 0.1, 3, 8), proved, 8, "a table")
    >>> check_certificate(ExhaustiveCheck(0.125, 0.1, 3, 8), proved, 8, "a table")
    Traceback (most recent call last):
    ...
    ValueError: certificate.upper: stated 1.250000e-01 but a table errs by up to 2.500000e-01 (at code 3); accepted: a bound the recomputed exhaustive proof supports
    """
    from chebnorm.core.numeric import format_up

    from .exhaustive import ExhaustiveCheck

    if not isinstance(cert, ExhaustiveCheck):
        raise ValueError(f"certificate: a {type(cert).__name__}; accepted: the ExhaustiveCheck "
                         f"of the design's codes")
    up, low = proved["upper"], proved["lower"]
    for name in ("upper", "lower"):
        v = getattr(cert, name)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v) or v < 0:
            raise ValueError(f"certificate.{name} {v!r}: accepted: a finite number >= 0")
    if not cert.upper >= up:
        raise ValueError(f"certificate.upper: stated {format_up(cert.upper, '.6e')} but {what} "
                         f"errs by up to {format_up(up, '.6e')} (at code {proved['at']}); "
                         f"accepted: a bound the recomputed exhaustive proof supports")
    if not cert.lower <= low:
        raise ValueError(f"certificate.lower: stated {cert.lower!r} but the proved lower bound "
                         f"of {what}'s error is {low!r}; accepted: at most that")
    if cert.codes != codes or isinstance(cert.at, bool) or not isinstance(cert.at, int) or \
            not 0 <= cert.at < codes:
        raise ValueError(f"certificate: codes {cert.codes!r}, at {cert.at!r}; accepted: "
                         f"codes {codes} and a code 0 <= at < {codes}")
