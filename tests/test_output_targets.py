"""``-o`` writes *through* what it must not replace (issue 26, item 5): an
existing device, FIFO or ``/dev/stdout`` is opened and written, a symbolic
link is written at its target, regular files and new paths keep the atomic
write (mode 0644), and a command that writes several files writes all of them
or none (item 10: a failed ``hw verilog`` or ``render`` left some behind)."""

from __future__ import annotations

import os
import stat
import subprocess
import sys
import threading

import pytest

from chebnorm.core.files import WriteError, write_all, write_atomic, write_folder
from conftest import run_process
from quiet_cli import run_cli_quiet as cli

ROOT = hasattr(os, "geteuid") and os.geteuid() == 0


@pytest.fixture(scope="module")
def table(tmp_path_factory):
    d = tmp_path_factory.mktemp("table")
    r = cli("fit", "1/sqrt(x)", "--interval", "1", "2", "--degree", "2", "--coef-frac-bits", "12",
            "-o", "t.json", cwd=d)
    assert r.code == 0, r.err
    return d / "t.json"


class _Reader(threading.Thread):
    """Reads a FIFO to its end (opening it blocks until a writer opens it)."""

    def __init__(self, path):
        super().__init__(daemon=True)
        self.path, self.data = path, None

    def run(self):
        with open(self.path, "rb") as fh:
            self.data = fh.read()


def _fifo(tmp_path):
    path = tmp_path / "pipe"
    os.mkfifo(path)
    reader = _Reader(path)
    reader.start()
    return path, reader


class TestWriter:
    def test_fifo_is_written_through(self, tmp_path):
        path, reader = _fifo(tmp_path)
        write_atomic(path, "hello\n")
        reader.join(30)
        assert not reader.is_alive() and reader.data == b"hello\n"
        assert stat.S_ISFIFO(os.lstat(path).st_mode)
        assert sorted(p.name for p in tmp_path.iterdir()) == ["pipe"]

    def test_symlink_is_written_at_its_target(self, tmp_path):
        (tmp_path / "real.h").write_text("old")
        (tmp_path / "link.h").symlink_to("real.h")
        write_atomic(tmp_path / "link.h", "new\n")
        assert (tmp_path / "link.h").is_symlink()
        assert os.readlink(tmp_path / "link.h") == "real.h"
        assert (tmp_path / "real.h").read_text() == "new\n"
        assert stat.S_IMODE(os.stat(tmp_path / "real.h").st_mode) == 0o644
        # a dangling link creates its target, the link stays
        (tmp_path / "sub").mkdir()
        (tmp_path / "dangling").symlink_to("sub/made.h")
        write_atomic(tmp_path / "dangling", "x")
        assert (tmp_path / "dangling").is_symlink() and (tmp_path / "sub" / "made.h").read_text() == "x"

    def test_open_file_link_is_written_through(self, tmp_path):
        """A link into /proc/PID/fd (what /dev/stdout is) names an open file: a
        regular file opened by the shell is written in place (its inode kept)."""
        out = tmp_path / "captured.txt"
        link = tmp_path / "my_stdout"
        link.symlink_to("/proc/self/fd/1")
        code = ("import sys; from chebnorm.core.files import write_atomic; "
                "write_atomic(sys.argv[1], 'through\\n')")
        with open(out, "w") as fh:
            inode = os.fstat(fh.fileno()).st_ino
            r = subprocess.run([sys.executable, "-c", code, str(link)], stdout=fh,
                               stderr=subprocess.PIPE, text=True, timeout=60)
        assert r.returncode == 0, r.stderr
        assert link.is_symlink() and os.readlink(link) == "/proc/self/fd/1"
        assert out.read_text() == "through\n" and os.stat(out).st_ino == inode
        # and into a pipe
        r = subprocess.run([sys.executable, "-c", code, str(link)], capture_output=True,
                           text=True, timeout=60)
        assert r.returncode == 0 and r.stdout == "through\n", r.stderr

    @pytest.mark.skipif(not ROOT, reason="mknod needs root")
    def test_character_device_is_written_through(self, tmp_path):
        """A private copy of /dev/null (char 1:3): the old writer replaced it by
        a regular file holding the output."""
        dev = tmp_path / "null"
        os.mknod(dev, stat.S_IFCHR | 0o666, os.makedev(1, 3))
        write_atomic(dev, "x" * 1000)
        st = os.lstat(dev)
        assert stat.S_ISCHR(st.st_mode) and st.st_rdev == os.makedev(1, 3)
        assert sorted(p.name for p in tmp_path.iterdir()) == ["null"]

    @pytest.mark.skipif(not ROOT, reason="mknod needs root")
    def test_block_device_is_refused(self, tmp_path):
        dev = tmp_path / "blk"
        os.mknod(dev, stat.S_IFBLK | 0o600, os.makedev(7, 250))
        with pytest.raises(WriteError, match="it is a block device; accepted: a new path"):
            write_atomic(dev, "x")
        assert stat.S_ISBLK(os.lstat(dev).st_mode)

    def test_several_files_all_or_none(self, tmp_path):
        (tmp_path / "a.txt").write_text("old a")
        (tmp_path / "b.txt").mkdir()  # the second destination cannot be written
        with pytest.raises(WriteError, match="b.txt'.*it is a directory"):
            write_all([(tmp_path / "a.txt", "new a"), (tmp_path / "b.txt", "b")])
        with pytest.raises(WriteError, match="does not exist"):
            write_all([(tmp_path / "a.txt", "new a"), (tmp_path / "no" / "c.txt", "c")])
        assert (tmp_path / "a.txt").read_text() == "old a"
        assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt", "b.txt"]

    def test_folder_removed_when_its_write_fails(self, tmp_path):
        with pytest.raises(WriteError, match="does not exist"):
            write_folder(tmp_path / "new" / "out", {"a.txt": "a", "../../missing/x": "x"})
        assert list(tmp_path.iterdir()) == []


@pytest.fixture
def system_links():
    """A safety net for the machine, not for the test: a writer that replaced
    /dev/stdout or /dev/null (the bug) would break every later process, so the
    originals are put back *and the test fails*."""
    yield
    broken = []
    if not os.path.islink("/dev/stdout"):
        broken.append("/dev/stdout")
        if ROOT:
            os.unlink("/dev/stdout")
            os.symlink("/proc/self/fd/1", "/dev/stdout")
    if not stat.S_ISCHR(os.lstat("/dev/null").st_mode):
        broken.append("/dev/null")
        if ROOT:
            os.unlink("/dev/null")
            os.mknod("/dev/null", stat.S_IFCHR | 0o666, os.makedev(1, 3))
            os.chmod("/dev/null", 0o666)
    assert not broken, f"replaced (and restored): {broken}"


class TestCommands:
    def test_export_to_a_fifo(self, tmp_path, table):
        path, reader = _fifo(tmp_path)
        r = cli("export", table, "--format", "c", "-o", path)
        reader.join(60)
        assert r.code == 0, r.err
        assert reader.data.startswith(b"/*") and b"#endif" in reader.data
        assert stat.S_ISFIFO(os.lstat(path).st_mode)

    def test_export_to_dev_stdout(self, table, system_links):
        before = os.readlink("/dev/stdout")
        # a child process: /dev/stdout is the process's own fd 1, which an
        # in-process run does not redirect
        r = run_process("export", table, "--format", "json", "-o", "/dev/stdout")
        assert r.returncode == 0, r.stderr
        assert r.stdout == table.read_text()
        assert os.path.islink("/dev/stdout") and os.readlink("/dev/stdout") == before

    def test_dev_stdout_appended_to_a_file_keeps_its_content(self, tmp_path, table,
                                                             system_links):
        # `chebnorm export ... -o /dev/stdout >> log`: the file is appended to, not truncated
        log = tmp_path / "log.txt"
        log.write_text("earlier line\n")
        with open(log, "a") as out:  # a child process: its fd 1 is the log file
            r = subprocess.run([sys.executable, "-m", "chebnorm", "export", str(table), "--format",
                                "json", "-o", "/dev/stdout"], stdout=out, stderr=subprocess.PIPE,
                               text=True, check=False)
        assert r.returncode == 0, r.stderr
        assert log.read_text() == "earlier line\n" + table.read_text()

    def test_export_to_dev_null(self, table, system_links):
        st = os.stat("/dev/null")
        r = cli("export", table, "--format", "c", "-o", "/dev/null")
        assert r.code == 0, r.err
        after = os.lstat("/dev/null")
        assert stat.S_ISCHR(after.st_mode) and (after.st_ino, after.st_rdev) == (st.st_ino, st.st_rdev)

    def test_fit_through_a_symlink(self, tmp_path):
        (tmp_path / "tables").mkdir()
        (tmp_path / "t.json").symlink_to("tables/real.json")
        r = cli("fit", "x", "--interval", "0", "1", "--degree", "1", "-o", "t.json", cwd=tmp_path)
        assert r.code == 0, r.err
        assert (tmp_path / "t.json").is_symlink()
        assert '"degree": 1' in (tmp_path / "tables" / "real.json").read_text()

    def test_failed_hw_verilog_writes_nothing(self, tmp_path, table):
        out = tmp_path / "hdl"
        out.mkdir()
        # a folder where one of the outputs (the bench) goes: that write fails
        (out / "tb_chebnorm_rsqrt_1_2_d2.v").mkdir()
        r = cli("hw", "verilog", table, "--in-bits", "8", "--out-bits", "8", "-o", out)
        assert r.code == 2 and r.err.count("\n") == 1, r.err
        assert "tb_chebnorm_rsqrt_1_2_d2.v" in r.err and "it is a directory" in r.err
        assert sorted(p.name for p in out.iterdir()) == ["tb_chebnorm_rsqrt_1_2_d2.v"]

    def test_failed_render_writes_nothing(self, tmp_path):
        r = cli("render", "--mesh", "square", "--tess", "2", "--size", "16", "16",
                "--out", "a.png", "--error-map", "missing/e.png", cwd=tmp_path)
        assert r.code == 2 and r.err.count("\n") == 1, r.err
        assert "missing/e.png" in r.err
        assert list(tmp_path.iterdir()) == []
