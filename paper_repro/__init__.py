"""Reproduction of the four papers' figures, tables and claims.

One module per paper, one function per figure or table. ``REGISTRY`` maps a
job name to a callable ``job(out_dir: pathlib.Path) -> list[pathlib.Path]``
returning the files it wrote; ``chebnorm repro`` finds it through the
``chebnorm.repro`` entry point and runs the jobs in sorted name order, so the
claims ledger (``zz_claims``) comes last. Uses chebnorm's public API only.

=====================  ======================  =====================
job                    module                  writes under figures/
=====================  ======================  =====================
``seed000_normalization`` :mod:`.normalization` ``normalization/``
``seed001_bump``       :mod:`.bump`            ``bump/``
``seed002_highlight``   :mod:`.highlight`       ``highlight/``
``seed003_criterion``  :mod:`.criterion`       ``criterion/``
``zz_claims``          :mod:`.claims`          ``claims/`` (+ ledger)
=====================  ======================  =====================
"""

from . import bump, claims, criterion, highlight, normalization

REGISTRY: dict = {
    criterion.JOB: criterion.run,
    normalization.JOB: normalization.run,
    bump.JOB: bump.run,
    highlight.JOB: highlight.run,
    claims.JOB: claims.run,
}
