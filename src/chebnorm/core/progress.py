"""Progress bars for long steps, written once.

Every step that can take more than a couple of seconds (exhaustive
certificates, verification over every float32, synthesis, sweeps) reports
through :func:`progress_bar`: a tqdm bar on stderr when stderr is a terminal,
nothing otherwise (a pipe, a log file, a test's captured stream, a notebook's
output), so scripted runs and outputs stay byte for byte the same.
"""

from __future__ import annotations

import os


def progress_bar(total: int, desc: str, *, unit: str = "it"):
    """A tqdm bar over ``total`` units, shown only on a terminal.

    ``CHEBNORM_PROGRESS=0`` hides it on a terminal too.

    Parameters
    ----------
    total : int
        The units of work.
    desc : str
        What is being done, as the bar's label.
    unit : str, optional
        The unit's name (``"input"``, ``"design"``).

    Returns
    -------
    tqdm.tqdm
        Use as a context manager; ``update(n)`` after each ``n`` units.

    Examples
    --------
    >>> with progress_bar(3, "counting") as bar:   # not a terminal here: silent
    ...     for _ in range(3):
    ...         _ = bar.update(1)
    """
    from tqdm import tqdm

    hidden = os.environ.get("CHEBNORM_PROGRESS") == "0"
    # disable=None: tqdm shows the bar only when stderr is a terminal
    return tqdm(total=total, desc=desc, unit=unit, unit_scale=True, leave=False,
                disable=True if hidden else None, dynamic_ncols=True)
