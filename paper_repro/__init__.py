"""Reproduction of the four papers' figures, tables and claims.

One module per paper, one function per figure or table. ``REGISTRY`` maps a
job name to a callable ``job(out_dir: pathlib.Path) -> list[pathlib.Path]``
returning the files it wrote; ``chebnorm repro`` finds it through the
``chebnorm.repro`` entry point. Uses chebnorm's public API only.
"""

REGISTRY: dict = {}
