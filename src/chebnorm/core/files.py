"""The one writer for every file chebnorm writes (images included).

* A new path or an existing regular file gets an atomic write: the data go to
  a temporary file in the same folder (mode 0644), which is then renamed into
  place, so a reader never sees a half-written output.
* A symbolic link is written through to its target, as editors do: the link
  is resolved and the atomic write happens at the file it names (a dangling
  link creates its target); the link itself stays.
* An existing file that is not a regular file (a character device such as
  ``/dev/null``, a FIFO, a socket, ``/dev/stdout`` and the ``/proc/self/fd``
  links behind it) is written through: opened for writing and written, never
  replaced. A block device is refused.
* :func:`write_all` writes several files all or none: every temporary is
  written first and only then are they renamed into place; if one fails, the
  temporaries are removed and no destination has changed.
* A destination that cannot be written is refused with one clear message
  naming it (:class:`WriteError`).

>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> write_atomic(folder / "a.txt", "hello\\n")
>>> (folder / "a.txt").read_text()
'hello\\n'
>>> write_atomic(folder, "x")
Traceback (most recent call last):
...
chebnorm.exceptions.WriteError: cannot write '...': it is a directory
"""

from __future__ import annotations

import errno
import os
import re
import stat
import tempfile
from pathlib import Path

from chebnorm.exceptions import WriteError


_REASONS = {
    errno.EACCES: "permission denied",
    errno.EPERM: "permission denied",
    errno.EROFS: "the file system is read-only",
    errno.ENOSPC: "no space left on the device",
    errno.EDQUOT: "disk quota exceeded",
    errno.EISDIR: "it is a directory",
    errno.ENOTDIR: "a component of the path is not a directory",
    errno.ENAMETOOLONG: "the file name is too long",
    errno.ELOOP: "too many levels of symbolic links",
    errno.ENXIO: "no process is reading it",
}


def _reason(exc: OSError) -> str:
    return _REASONS.get(exc.errno, exc.strerror or type(exc).__name__)


def _refuse(path, reason: str) -> WriteError:
    return WriteError(f"cannot write {str(path)!r}: {reason}")


_OPEN_FILE = re.compile(r"/proc/[^/]+/(task/[^/]+/)?fd/[^/]+")


def _names_open_file(path: Path) -> bool:
    """Whether ``path``'s symbolic links pass through ``/proc/PID/fd/N``
    (``/dev/stdout`` -> ``/proc/self/fd/1``): such a link names a file a
    process has open, which is written through, never replaced (its shell may
    have opened it for appending, or it is a pipe)."""
    p = os.path.abspath(path)
    for _ in range(40):
        p = os.path.join(os.path.realpath(os.path.dirname(p)), os.path.basename(p))
        if _OPEN_FILE.fullmatch(p):
            return True
        if not os.path.islink(p):
            return False
        p = os.path.normpath(os.path.join(os.path.dirname(p), os.readlink(p)))
    return False


def _plan(path) -> tuple[str, Path, Path]:
    """``(how, given, target)``: ``how`` is ``"atomic"`` (temporary file and
    rename at ``target``) or ``"through"`` (open ``given`` and write)."""
    given = Path(path)
    try:
        st = os.stat(given)
    except FileNotFoundError:
        st = None
    except OSError as exc:
        if exc.errno not in (errno.ENOTDIR, errno.EACCES):
            raise _refuse(given, _reason(exc)) from None
        st = None
    if st is not None and stat.S_ISDIR(st.st_mode):
        raise _refuse(given, "it is a directory")
    if st is not None and stat.S_ISBLK(st.st_mode):
        raise _refuse(given, "it is a block device; accepted: a new path, a regular file, a "
                             "character device or a FIFO")
    if st is not None and (not stat.S_ISREG(st.st_mode) or _names_open_file(given)):
        return "through", given, given
    if st is None and _names_open_file(given):
        raise _refuse(given, "it is a link to an open file that no longer exists")
    target = Path(os.path.realpath(given)) if os.path.islink(given) else given
    folder = target.parent if str(target.parent) else Path(".")
    if target.is_dir():
        raise _refuse(given, "it is a directory")
    if not folder.exists():
        raise _refuse(given, f"folder {str(folder)!r} does not exist")
    if not folder.is_dir():
        raise _refuse(given, f"{str(folder)!r} is not a folder")
    return "atomic", given, target


def _as_bytes(data: str | bytes) -> bytes:
    """Text as UTF-8 with ``\\n`` line ends, bytes unchanged."""
    return data if isinstance(data, bytes) else data.encode("utf-8")


def _stage(given: Path, target: Path, data: bytes) -> str:
    """Write ``data`` into a new temporary file (mode 0644) beside ``target``;
    returns its path. Nothing is left behind on failure."""
    folder = target.parent if str(target.parent) else Path(".")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=folder)
    except OSError as exc:
        reason = "it does not accept new files" if exc.errno == errno.ENOENT else _reason(exc)
        raise _refuse(given, f"cannot create a file in folder {str(folder)!r} ({reason})") from None
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(tmp, 0o644)
    except OSError as exc:
        _unlink_quietly(tmp)
        raise _refuse(given, _reason(exc)) from None
    except BaseException:
        _unlink_quietly(tmp)
        raise
    return tmp


def _write_through(given: Path, data: bytes) -> None:
    """Open the existing non-regular file ``given`` (a device, a FIFO, a
    process's open file) and write ``data`` into it; never creates or
    replaces it. A FIFO without a reader blocks until one opens it, as a
    shell redirection does."""
    flags = os.O_WRONLY | os.O_NOCTTY | getattr(os, "O_CLOEXEC", 0)
    try:
        # a regular file reached through /dev/stdout (``-o /dev/stdout >> log``) is
        # appended to, never truncated: the shell's redirection decides what it holds
        regular = stat.S_ISREG(os.stat(given).st_mode)
        fd = os.open(given, flags | (os.O_APPEND if regular else os.O_TRUNC))
    except OSError as exc:
        raise _refuse(given, _reason(exc)) from None
    try:
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view):]
    except BrokenPipeError:
        raise  # the reader went away: the CLI ends quietly, as with a closed stdout
    except OSError as exc:
        raise _refuse(given, _reason(exc)) from None
    finally:
        os.close(fd)


def write_all(items) -> None:
    """Write several files, all or none: ``items`` is an iterable of
    ``(path, data)`` (``data`` text, written as UTF-8 with ``\\n`` line ends,
    or bytes). Each destination follows the rules of the module docstring.

    Parameters
    ----------
    items : iterable of (path, str or bytes)
        The destinations and their contents.

    Every destination is checked and every temporary file written before any
    is renamed into place; when one fails, the temporaries are removed and
    :class:`WriteError` names the destination, so no regular file has
    changed. Destinations written through (devices, FIFOs) are written after
    the temporaries and before the renames.

    Raises
    ------
    WriteError
        when a path is a directory, its folder does not exist or is not a
        folder, or the system refuses the write (permissions, read-only file
        system, full disk, ``/proc``...).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     d = pathlib.Path(tmp)
    ...     try:
    ...         write_all([(d / "a.txt", "a"), (d / "no" / "b.txt", "b")])
    ...     except WriteError as exc:
    ...         print(exc.args[0].split(":")[-1], sorted(p.name for p in d.iterdir()))
    ...     write_all([(d / "a.txt", "a"), (d / "b.txt", b"b")])
    ...     print(sorted(p.name for p in d.iterdir()))
    ...  # doctest: +ELLIPSIS
     folder '...' does not exist []
    ['a.txt', 'b.txt']
    """
    plans = [(_plan(path), _as_bytes(data)) for path, data in items]
    staged: list[tuple[str, Path, Path]] = []
    try:
        for (how, given, target), data in plans:
            if how == "atomic":
                staged.append((_stage(given, target, data), given, target))
        for (how, given, _), data in plans:
            if how == "through":
                _write_through(given, data)
        while staged:
            tmp, given, target = staged[0]
            try:
                os.replace(tmp, target)
            except OSError as exc:
                raise _refuse(given, _reason(exc)) from None
            staged.pop(0)
    finally:
        for tmp, _, _ in staged:
            _unlink_quietly(tmp)


def _same_file(a, b) -> bool:
    """Whether paths ``a`` and ``b`` name one file: the same real path
    (symbolic links resolved) or, when both exist, the same inode (a hard
    link)."""
    if os.path.realpath(a) == os.path.realpath(b):
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def refuse_inputs(outputs, inputs) -> None:
    """Refuse an output that would replace an input of the same command.

    Parameters
    ----------
    outputs : dict of str to (str or os.PathLike)
        What each destination is (``"-o"``, ``"--json"``, ``"proof file"``)
        -> its path.
    inputs : dict of str to (str or os.PathLike)
        What each input is (``"TABLE.json"``) -> its path; ``None`` paths are
        skipped.

    Raises
    ------
    WriteError
        Naming the output, its path and the input it resolves to (through
        symbolic links, or a hard link to the same file).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     t = pathlib.Path(tmp) / "t.json"
    ...     _ = t.write_text("{}")
    ...     refuse_inputs({"-o": pathlib.Path(tmp) / "t.h"}, {"TABLE.json": t})
    ...     try:
    ...         refuse_inputs({"-o": pathlib.Path(tmp) / "." / "t.json"}, {"TABLE.json": t})
    ...     except WriteError as exc:
    ...         print(str(exc).split()[0], "is the input" in str(exc))
    -o True
    """
    for what, out in outputs.items():
        for role, src in inputs.items():
            if src is not None and out is not None and _same_file(out, src):
                raise WriteError(f"{what} {str(out)!r:.200} is the input {role} "
                                 f"{str(src)!r:.200}; an output never replaces an input: "
                                 f"choose another file name")


def check_writable(paths) -> None:
    """Refuse, before any work, the destinations :func:`write_all` would refuse:
    the same checks, and for a file to be replaced atomically a temporary file
    created and removed in its folder (``/proc`` and read-only folders say no
    only then). Nothing is written.

    Parameters
    ----------
    paths : iterable of str or os.PathLike
        The destinations a command will write once its work is done.

    Raises
    ------
    WriteError
        Naming the first destination that cannot be written and why, as
        :func:`write_all` would after the work.

    Examples
    --------
    >>> check_writable(["/proc/x.png"])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    chebnorm.exceptions.WriteError: cannot write '/proc/x.png': cannot create a file in folder '/proc' ...
    """
    for path in paths:
        how, given, target = _plan(path)
        if how == "atomic":
            _unlink_quietly(_stage(given, target, b""))


def write_atomic(path, data: str | bytes) -> None:
    """Write ``data`` to ``path``: a new path or a regular file through a
    temporary file in the same folder renamed into place (atomic on POSIX,
    mode 0644); a symbolic link at its target; an existing device, FIFO or
    ``/dev/stdout`` written through, never replaced (module docstring).

    Text is written as UTF-8 with ``\\n`` line ends, bytes unchanged.

    Parameters
    ----------
    path : str or os.PathLike
        The destination.
    data : str or bytes
        The contents.

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
    write_all([(path, data)])


def write_folder(directory, files) -> list[Path]:
    """Write ``files`` (name -> text or bytes) into ``directory``, all or
    none (:func:`write_all`); the folder is created if missing, and removed
    again when the write fails.

    Parameters
    ----------
    directory : str or os.PathLike
        The folder (created with its parents if missing).
    files : dict of str to (str or bytes)
        File name -> contents, written in this order.

    Returns
    -------
    list of pathlib.Path
        The paths written, in the order of ``files``.

    Raises
    ------
    WriteError
        When a file cannot be written (nothing is left behind).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> d = pathlib.Path(tempfile.mkdtemp()) / "out"
    >>> [p.name for p in write_folder(d, {"b.txt": "b", "a.txt": "a"})]
    ['b.txt', 'a.txt']
    """
    folder = Path(directory)
    created = []
    p = folder
    while not os.path.lexists(p) and p != p.parent:
        created.append(p)
        p = p.parent
    make_folder(folder)
    paths = [folder / name for name in files]
    try:
        write_all(zip(paths, files.values()))
    except BaseException:
        for p in created:  # innermost first; a folder someone filled meanwhile stays
            try:
                os.rmdir(p)
            except OSError:
                break
        raise
    return paths


def make_folder(path) -> Path:
    """Create folder ``path`` (and its parents) if missing and return it.

    Parameters
    ----------
    path : str or os.PathLike
        The folder.

    Returns
    -------
    pathlib.Path
        ``path`` as a Path, an existing folder.

    Raises
    ------
    WriteError
        Naming ``path`` when it exists as a file or cannot be created.

    Examples
    --------
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
                  else _reason(exc))
        raise WriteError(f"cannot create folder {str(path)!r}: {reason}") from None
    return path


def _unlink_quietly(tmp: str) -> None:
    try:
        os.unlink(tmp)
    except OSError:
        pass
