"""Atomic file writing, the one writer for every file chebnorm writes (images
included): a reader never sees a half-written output, and a destination that
cannot be written is refused with one clear message naming it.

>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> write_atomic(folder / "a.txt", "hello\\n")
>>> (folder / "a.txt").read_text()
'hello\\n'
>>> write_atomic(folder, "x")
Traceback (most recent call last):
...
chebnorm.approx.files.WriteError: cannot write '...': it is a directory
"""

from __future__ import annotations

import errno
import os
import tempfile
from pathlib import Path

__all__ = ["write_atomic", "make_folder", "WriteError"]


class WriteError(OSError, ValueError):
    """A destination chebnorm cannot write: the message names the path the
    caller gave (never a temporary file) and the reason. It is an ``OSError``
    and a ``ValueError``, so the command line reports it as a user error
    (exit status 2, one line).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     try:
    ...         write_atomic(pathlib.Path(tmp) / "missing" / "t.txt", "x")
    ...     except WriteError as exc:
    ...         print(isinstance(exc, ValueError), isinstance(exc, OSError))
    True True
    """


_REASONS = {
    errno.EACCES: "permission denied",
    errno.EPERM: "permission denied",
    errno.EROFS: "the file system is read-only",
    errno.ENOSPC: "no space left on the device",
    errno.EDQUOT: "disk quota exceeded",
    errno.EISDIR: "it is a directory",
    errno.ENOTDIR: "a component of the path is not a directory",
    errno.ENAMETOOLONG: "the file name is too long",
}


def _refuse(path: Path, reason: str) -> WriteError:
    return WriteError(f"cannot write {str(path)!r}: {reason}")


def write_atomic(path, data: str | bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder,
    then rename it into place (atomic on POSIX); the file gets mode 0644.

    Text is written as UTF-8 with ``\\n`` line ends, bytes unchanged.

    Raises
    ------
    WriteError
        when ``path`` is a directory, its folder does not exist or is not a
        folder, or the system refuses the write (permissions, read-only file
        system, full disk, ``/proc``...). The message names ``path`` as given
        and the reason; no temporary file is left behind.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     write_atomic(pathlib.Path(tmp) / "t.csv", "a,b\\n1,2\\n")
    ...     print(repr((pathlib.Path(tmp) / "t.csv").read_bytes()))
    b'a,b\\n1,2\\n'
    """
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if path.is_dir():
        raise _refuse(path, "it is a directory")
    if not folder.exists():
        raise _refuse(path, f"folder {str(folder)!r} does not exist")
    if not folder.is_dir():
        raise _refuse(path, f"{str(folder)!r} is not a folder")
    mode = "wb" if isinstance(data, bytes) else "w"
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    except OSError as exc:
        reason = ("it does not accept new files" if exc.errno == errno.ENOENT
                  else _REASONS.get(exc.errno, exc.strerror or type(exc).__name__))
        raise _refuse(path, f"cannot create a file in folder {str(folder)!r} ({reason})") from None
    try:
        with os.fdopen(fd, mode, **({} if mode == "wb" else {"encoding": "utf-8", "newline": "\n"})) as fh:
            fh.write(data)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except OSError as exc:
        _unlink_quietly(tmp)
        raise _refuse(path, _REASONS.get(exc.errno, exc.strerror or type(exc).__name__)) from None
    except BaseException:
        _unlink_quietly(tmp)
        raise


def make_folder(path) -> Path:
    """Create folder ``path`` (and its parents) if missing and return it;
    raises :class:`WriteError` naming ``path`` when it exists as a file or
    cannot be created.

    >>> import tempfile, pathlib
    >>> make_folder(pathlib.Path(tempfile.mkdtemp()) / "a" / "b").is_dir()
    True
    """
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise WriteError(f"cannot write into {str(path)!r}: it exists and is not a folder")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        reason = ("its parent does not accept new folders" if exc.errno == errno.ENOENT
                  else _REASONS.get(exc.errno, exc.strerror or type(exc).__name__))
        raise WriteError(f"cannot create folder {str(path)!r}: {reason}") from None
    return path


def _unlink_quietly(tmp: str) -> None:
    try:
        os.unlink(tmp)
    except OSError:
        pass
