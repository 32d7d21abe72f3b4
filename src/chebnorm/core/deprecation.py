"""Old spellings of arguments, accepted for one release with a warning.

One word per concept across the API, the CLI and the messages (the docs'
glossary); an argument renamed to that word keeps its old keyword for one
release through :func:`renamed`, which warns with
:class:`ChebnormDeprecationWarning`.
"""

from __future__ import annotations

import warnings

from chebnorm.exceptions import ChebnormDeprecationWarning


def renamed(old_value, new_value, old: str, new: str, func: str, *, stacklevel: int = 3):
    """The value of an argument renamed from ``old`` to ``new``.

    Parameters
    ----------
    old_value, new_value : object
        What the caller passed under each name (None: not passed).
    old, new : str
        The two keywords.
    func : str
        The function's name, for the messages.
    stacklevel : int, optional
        Where the warning points (3: the caller of the function calling this).

    Returns
    -------
    object
        ``new_value``, or ``old_value`` (with a :class:`ChebnormDeprecationWarning`)
        when only the old keyword was given.

    Raises
    ------
    ValueError
        When both keywords were given.

    Examples
    --------
    >>> renamed(None, 16, "frac_bits", "coef_frac_bits", "fit")
    16
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as w:
    ...     warnings.simplefilter("always")
    ...     renamed(16, None, "frac_bits", "coef_frac_bits", "fit", stacklevel=2)
    ...     w[0].category.__name__
    16
    'ChebnormDeprecationWarning'
    """
    if old_value is None:
        return new_value
    if new_value is not None:
        raise ValueError(f"{func}: give {new} only ({old} is its deprecated spelling)")
    warnings.warn(f"{func}({old}=...) is deprecated and will be removed in the next release; "
                  f"use {new}=", ChebnormDeprecationWarning, stacklevel=stacklevel)
    return old_value
