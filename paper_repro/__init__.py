"""Reproduction of the four papers' figures, tables and claims.

One module per paper, one function per figure or table. ``REGISTRY`` maps a
job name to a callable ``job(out_dir, *, bench_results=None, ledger_dir=None)
-> list[pathlib.Path]`` returning the files it wrote; ``chebnorm repro`` finds
it through the ``chebnorm.repro`` entry point and runs the jobs in sorted name
order, so the claims ledger (``zz_claims``) comes last. ``bench_results`` and
``ledger_dir`` are ``--bench-results`` and ``--ledger-dir`` (None: the
defaults of :mod:`.paths`, taken from the current directory). Uses chebnorm's
public API only.

=====================  ======================  =====================
job                    module                  writes under figures/
=====================  ======================  =====================
``seed000_normalization`` :mod:`.normalization` ``normalization/``
``seed001_bump``       :mod:`.bump`            ``bump/``
``seed002_highlight``   :mod:`.highlight`       ``highlight/``
``seed003_criterion``  :mod:`.criterion`       ``criterion/``
``zz_claims``          :mod:`.claims`          the ledger (:func:`.paths.ledger_dir`)
=====================  ======================  =====================
"""

from functools import wraps

from . import benchmarks, bump, claims, criterion, highlight, normalization


def _job(run, takes_ledger: bool = False):
    @wraps(run)
    def job(out, *, bench_results=None, ledger_dir=None):
        benchmarks.use_results(bench_results)
        return run(out, ledger_dir) if takes_ledger else run(out)
    return job


REGISTRY: dict = {
    criterion.JOB: _job(criterion.run),
    normalization.JOB: _job(normalization.run),
    bump.JOB: _job(bump.run),
    highlight.JOB: _job(highlight.run),
    claims.JOB: _job(claims.run, takes_ledger=True),
}
