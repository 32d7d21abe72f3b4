"""Every script under figures/ runs as the documentation shows it
(``python figures/<topic>/<script>.py``) and writes the committed bytes.

Each runs as a program (a child process is the point: the script's own imports
and ``__main__``), on a copy in a temporary folder so the committed outputs are
compared, not rewritten."""

import shutil
import sys
from pathlib import Path

import pytest



ROOT = Path(__file__).resolve().parent.parent
SCRIPTS = sorted((ROOT / "figures").glob("*/*.py"))


def _gl_missing() -> str | None:
    from chebnorm.export.gpu import ToolMissing, gl_context

    try:
        gl_context()
    except ToolMissing as exc:
        return str(exc)
    return None


def test_every_figure_script_is_listed_here():
    assert [p.relative_to(ROOT).as_posix() for p in SCRIPTS] == ["figures/shaders/shader_demo.py"]


@pytest.mark.slow
def test_shader_demo_writes_the_committed_outputs(tmp_path):
    import subprocess

    reason = _gl_missing()
    if reason:
        pytest.skip(reason)
    script = ROOT / "figures" / "shaders" / "shader_demo.py"
    copy = tmp_path / "figures" / "shaders" / script.name
    copy.parent.mkdir(parents=True)
    shutil.copyfile(script, copy)
    # the tables it reads, where the script looks for them (beside its own folder)
    (tmp_path / "figures" / "coefficients").symlink_to(ROOT / "figures" / "coefficients")
    done = subprocess.run([sys.executable, str(copy)], cwd=tmp_path, capture_output=True,
                          text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
    for name in ("shader_demo.csv", "shader_demo.png"):
        assert (copy.parent / name).read_bytes() == (script.parent / name).read_bytes(), name
    assert done.stdout == (script.parent / "shader_demo.csv").read_text(encoding="utf-8")
