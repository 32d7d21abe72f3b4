"""Scale-out: map_ordered and the --workers / --scheduler options give the same bytes
as a serial run (local processes and a Dask LocalCluster)."""

import math

import numpy as np
import pytest

from chebnorm.core.parallel import check_workers, map_ordered
from conftest import run_process
from quiet_cli import run_cli_quiet


def _square_slow_first(x):
    import time
    time.sleep(0.3 if x == 0 else 0.0)   # the first item finishes last
    return x * x


def test_map_ordered_keeps_item_order():
    seen = []
    got = map_ordered(_square_slow_first, range(5), workers=2,
                      on_result=lambda i, r: seen.append(i))
    assert got == [0, 1, 4, 9, 16]
    assert sorted(seen) == [0, 1, 2, 3, 4]
    assert map_ordered(math.sqrt, [], workers=2) == []


@pytest.mark.parametrize("bad", [0, -1, 1.5, True, "2"])
def test_bad_workers(bad):
    with pytest.raises(ValueError, match="accepted: an integer >= 1"):
        check_workers(bad)


SWEEP = ["hw", "sweep", "--degrees", "1", "2", "--coef-frac-bits", "10", "14",
         "--acc-bits", "16"]


def test_hw_sweep_workers_same_bytes(tmp_path):
    # each run a fresh process, as from a shell: in this one the serial run would leave
    # its caches (and this process's hash seed) to the runs it is compared with
    for w in ("1", "2"):
        r = run_process(*SWEEP, "-o", str(tmp_path / w), "--workers", w, cwd=tmp_path)
        assert r.returncode == 0, r.stderr
    a = (tmp_path / "1" / "sweep_dichotomy.csv").read_bytes()
    assert a == (tmp_path / "2" / "sweep_dichotomy.csv").read_bytes()
    assert a.count(b"\n") == 1 + 2 + 2   # header, 2 degree-1 and 2 degree-2 designs
    r = run_cli_quiet(*SWEEP, "-o", str(tmp_path / "0"), "--workers", "0", cwd=tmp_path)
    assert r.code == 2 and r.err.strip().count("\n") == 0
    assert "accepted: an integer >= 1" in r.err and not (tmp_path / "0").exists()


def test_scheduler_needs_a_reachable_address(tmp_path):
    pytest.importorskip("distributed", reason="dask.distributed is not installed "
                        "(pip install 'chebnorm[cluster]')")
    r = run_cli_quiet("repro", "coefficients", "-o", str(tmp_path / "o"), "--scheduler",
                      "tcp://127.0.0.1:9", cwd=tmp_path)
    assert r.code == 2 and "cannot reach the Dask scheduler" in r.err


def test_dask_local_cluster_same_bytes(tmp_path):
    distributed = pytest.importorskip("distributed", reason="dask.distributed is not installed "
                                      "(pip install 'chebnorm[cluster]')")
    from chebnorm.methods.analysis import error_sweep

    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  protocol="tcp://", dashboard_address=None) as cluster:
        # the CLI, on the cluster's address; each run a fresh process (no caches shared
        # between the runs compared)
        r = run_process(*SWEEP, "-o", str(tmp_path / "d"), "--scheduler", cluster.scheduler_address,
                        cwd=tmp_path)
        assert r.returncode == 0, r.stderr
        r = run_process(*SWEEP, "-o", str(tmp_path / "s"), "--workers", "1", cwd=tmp_path)
        assert r.returncode == 0, r.stderr
        assert ((tmp_path / "d" / "sweep_dichotomy.csv").read_bytes()
                == (tmp_path / "s" / "sweep_dichotomy.csv").read_bytes())
        # the library, with a client
        with distributed.Client(cluster) as client:
            a = error_sweep(("none", "dichotomy"), [0.1, 0.5], (8, 13))
            b = error_sweep(("none", "dichotomy"), [0.1, 0.5], (8, 13), scheduler=client)
    for f in ("length_error", "angle_error", "diffuse_error", "specular_error"):
        x, y = np.asarray(getattr(a, f)), np.asarray(getattr(b, f))
        assert x.tobytes() == y.tobytes(), f
