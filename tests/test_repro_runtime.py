"""``chebnorm repro`` at run time (issue 44): silent about numba compiling its
kernels on a fresh machine, and a clean exit at Ctrl-C."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
import warnings
from pathlib import Path

import pytest

from chebnorm.approx import FitWarning
from chebnorm.cli import repro
from conftest import run_cli
from quiet_cli import run_cli_quiet

ROOT = Path(__file__).resolve().parents[1]


def _render_job(out, **_options):
    """A repro job whose render compiles (announced at once: ANNOUNCE_AFTER = 0)."""
    import chebnorm as cn

    cn.render("sphere", "gouraud", size=(16, 16), tess=4, engine="numba")
    return []


@pytest.fixture
def announcing(monkeypatch):
    """numba's first compile announced however quick (as on a fresh machine)."""
    pytest.importorskip("numba")
    from chebnorm.raster.engines import get_engine
    from chebnorm.raster.engines.numba import jit

    monkeypatch.setattr(get_engine("numba"), "warmed", set())
    monkeypatch.setattr(jit, "_ANNOUNCED", threading.Event())
    monkeypatch.setattr(jit, "ANNOUNCE_AFTER", 0.0)
    return jit


def test_render_announces_its_compile_outside_repro(announcing):
    # the check below can fail: outside repro the announcement is made
    import chebnorm as cn

    with pytest.warns(announcing.NumbaCompileWarning):
        cn.render("sphere", "gouraud", size=(16, 16), tess=4, engine="numba")


def test_repro_prints_no_compile_warning(announcing, monkeypatch, tmp_path):
    monkeypatch.setattr(repro, "jobs", lambda: {"render": _render_job})
    r = run_cli_quiet("repro", "render", "-o", tmp_path / "o", "--workers", "1", cwd=tmp_path)
    assert r.code == 0, r.err
    assert r.err == "" and r.out.startswith("chebnorm repro: 1 job(s), 1 file(s)")


def test_repro_passes_chebnorm_warnings_on(announcing, monkeypatch, tmp_path):
    def warning_job(out, **_options):
        warnings.warn("a fit warning", FitWarning)
        return _render_job(out)

    monkeypatch.setattr(repro, "jobs", lambda: {"warns": warning_job})
    code, _, err = run_cli("repro", "warns", "-o", tmp_path / "o", "--workers", "1",
                           cwd=tmp_path)
    assert code == 0
    assert err.splitlines() == ["chebnorm: warning: a fit warning"]


def _env(tmp_path):
    """A fresh numba cache (a first run on this machine), the worktree's chebnorm."""
    cache = tmp_path / "numba_cache"
    cache.mkdir()
    path = os.pathsep.join([str(ROOT / "src"), str(ROOT), os.environ.get("PYTHONPATH", "")])
    return dict(os.environ, NUMBA_CACHE_DIR=str(cache), PYTHONPATH=path, CHEBNORM_PROGRESS="0")


@pytest.mark.slow
def test_repro_on_an_empty_numba_cache_writes_no_warning(tmp_path):
    pytest.importorskip("numba")
    out = tmp_path / "o"
    # two jobs on two workers: the render job compiles in a worker process
    proc = subprocess.run([sys.executable, "-m", "chebnorm", "repro", "coefficients",
                           "seed001_bump", "-o", str(out), "--ledger-dir", str(out / "claims"),
                           "--workers", "2"], capture_output=True, text=True, timeout=600,
                          cwd=tmp_path, env=_env(tmp_path))
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ""
    assert len(proc.stdout.splitlines()) == 1 and "2 job(s)" in proc.stdout
    assert any((tmp_path / "numba_cache").rglob("*.nbi"))   # numba did compile into it


@pytest.mark.slow
def test_repro_ctrl_c_exits_130_and_keeps_what_finished(tmp_path):
    """Ctrl-C at a terminal: SIGINT to the whole process group (the command and its
    workers) while workers compute; one line, status 130, no traceback, no
    multiprocessing resource-tracker warning, the finished job's files kept."""
    out = tmp_path / "o"
    proc = subprocess.Popen([sys.executable, "-m", "chebnorm", "repro", "coefficients",
                             "seed001_bump", "seed002_highlight", "-o", str(out),
                             "--ledger-dir", str(out / "claims"), "--workers", "2"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            cwd=tmp_path, env=_env(tmp_path), start_new_session=True)
    committed = sorted(p.name for p in (ROOT / "figures" / "coefficients").iterdir())
    try:
        deadline = time.monotonic() + 300
        # the first job done: every file it writes is there (each written atomically)
        while not all((out / "coefficients" / name).exists() for name in committed):
            assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
            time.sleep(0.05)
        time.sleep(0.5)   # the two render jobs are running (each takes many seconds)
        os.killpg(proc.pid, signal.SIGINT)
        stdout, stderr = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()
    assert proc.returncode == 130, stderr
    assert stderr == "chebnorm: interrupted\n"   # no "leaked semaphore", no traceback
    assert stdout == ""
    for name in committed:   # the finished job's files, whole
        assert (out / "coefficients" / name).read_bytes() == \
            (ROOT / "figures" / "coefficients" / name).read_bytes(), name
    assert not (out / "provenance.json").exists()   # the run did not finish
    # nothing of the run is left running: workers and resource tracker gone (a zombie
    # is dead, waiting for a reaper that a container's init may not be)
    time.sleep(0.5)
    ps = subprocess.run(["ps", "-o", "pid=,stat=,args=", "-s", str(proc.pid)],
                        capture_output=True, text=True)
    assert not [ln for ln in ps.stdout.splitlines() if ln.split()[1][0] != "Z"], ps.stdout
