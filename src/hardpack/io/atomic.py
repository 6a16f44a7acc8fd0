"""Atomic file replacement: write to a temporary file in the destination folder, then rename.

A crash (even SIGKILL) leaves either the old file or the new one, never a half-written one; the
temporary file is removed when the writer raises. The new file gets the mode a plain ``open(path,
"w")`` would give it: the mode of the file it replaces, or ``0o666`` less the process umask (0644
under the usual umask 022) for a new file.

:func:`check_writable` tells before a long run whether its output paths can be written at all.
"""

from __future__ import annotations

import contextlib
import os
import stat
import tempfile
from pathlib import Path

from hardpack.errors import InvalidInputError


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _new_file_mode(path: Path) -> int:
    try:
        return stat.S_IMODE(os.stat(path).st_mode)
    except OSError:
        return 0o666 & ~_umask()


@contextlib.contextmanager
def atomic_path(path, fsync: bool = True):
    """Yield a temporary path next to ``path``; on success flush it and rename it onto ``path``.

    Missing parent folders are created.

    Parameters
    ----------
    path : str or os.PathLike
        The destination.
    fsync : bool, optional
        Flush the file to disk before the rename.

    Yields
    ------
    pathlib.Path
        The temporary path to write (removed if the block raises).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    try:
        yield Path(tmp)
        if fsync:
            with open(tmp, "rb+") as fh:
                os.fsync(fh.fileno())
        os.chmod(tmp, _new_file_mode(path))
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def write_text(path, text: str) -> None:
    """Atomically write a text file.

    Parameters
    ----------
    path : str or os.PathLike
        The destination.
    text : str
        The contents.
    """
    with atomic_path(path) as tmp:
        tmp.write_text(text)


def check_writable(path, what: str = "output") -> None:
    """Refuse, before any work, an output path that :func:`atomic_path` could not write.

    The path must not be a folder, and its nearest existing ancestor must be a folder in which a
    file can be created (folders still missing below it are created at write time). The check
    creates and removes a temporary file there, so it also catches read-only file systems and
    permissions that ``os.access`` does not see. Raises :class:`InvalidInputError` naming ``what``
    (e.g. the command-line option) and the path.

    Parameters
    ----------
    path : str or os.PathLike
        The output path.
    what : str, optional
        What the path is, for the message.
    """
    path = Path(path)
    if path.is_dir():
        raise InvalidInputError(f"{what} {path} is a folder; give a file path such as "
                                f"{path / 'result.nc'}")
    folder = path.absolute().parent
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    if not folder.is_dir():
        raise InvalidInputError(f"{what} {path} cannot be written: {folder} is a file, not a folder")
    try:
        fd, probe = tempfile.mkstemp(dir=folder, prefix=".hardpack-write-test.")
    except OSError as exc:
        raise InvalidInputError(f"{what} {path} cannot be written: cannot create files in folder "
                                f"{folder} ({exc.strerror}); choose a writable location") from None
    os.close(fd)
    os.unlink(probe)
