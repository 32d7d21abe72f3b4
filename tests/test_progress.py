"""Long steps show a progress bar on a terminal and nothing elsewhere."""

import fcntl
import os
import pty
import struct
import subprocess
import sys
import termios

import pytest

from chebnorm.core.progress import progress_bar


def _on_a_terminal(code: str, env=None) -> str:
    """What ``python -c code`` writes to a pseudo-terminal as its stderr (a child
    process: a terminal is the point)."""
    leader, follower = pty.openpty()
    # a terminal of 24 x 100 (a new pseudo-terminal is 0 x 0, and tqdm draws nothing there)
    fcntl.ioctl(follower, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))
    try:
        proc = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.DEVNULL,
                                stdout=subprocess.DEVNULL, stderr=follower, env=env)
        os.close(follower)
        chunks = []
        while True:
            try:
                data = os.read(leader, 4096)
            except OSError:  # the child closed the terminal
                break
            if not data:
                break
            chunks.append(data)
        assert proc.wait(timeout=600) == 0
    finally:
        os.close(leader)
    return b"".join(chunks).decode("utf-8", "replace")


COUNT = "from chebnorm.core.progress import progress_bar\n" \
        "with progress_bar(5, 'counting things', unit='thing') as b:\n" \
        "    [b.update(1) for _ in range(5)]\n"


def test_silent_when_stderr_is_not_a_terminal(capsys):
    with progress_bar(5, "counting things") as bar:
        bar.update(5)
    assert capsys.readouterr() == ("", "")


def test_shown_on_a_terminal():
    assert "counting things" in _on_a_terminal(COUNT)


def test_hidden_on_a_terminal_when_asked():
    env = dict(os.environ, CHEBNORM_PROGRESS="0")
    assert "counting things" not in _on_a_terminal(COUNT, env=env)


@pytest.mark.slow
def test_exhaustive_float32_certificate_shows_progress():
    code = ("import chebnorm as cn\n"
            "t = cn.fit('exp(x)', (1, 2), 6, kind='minimax', basis='monomial')\n"
            "assert 'exhaustive' in cn.export(t, 'c')\n")
    assert "float32 certificate" in _on_a_terminal(code)


@pytest.mark.slow
def test_verify_shows_progress_per_variant(tmp_path):
    code = ("import chebnorm as cn\n"
            "from chebnorm.export.verify import verify\n"
            "t = cn.fit('1/sqrt(x)', (1, 4), 3, basis='monomial', name='rs')\n"
            "assert verify(t, 'c', variant='float').passed\n")
    assert "chebnorm verify: chebnorm_rs_f (float)" in _on_a_terminal(code)


def test_parallel_map_bar_only_on_a_terminal(capsys):
    from chebnorm.core.parallel import map_ordered

    assert map_ordered(abs, [-1, -2], workers=1, progress=True, desc="mapping") == [1, 2]
    assert capsys.readouterr() == ("", "")
    code = ("from chebnorm.core.parallel import map_ordered\n"
            "map_ordered(abs, [-1, -2], workers=1, progress=True, desc='mapping things')\n")
    assert "mapping things" in _on_a_terminal(code)
