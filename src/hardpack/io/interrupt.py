"""Graceful stops of long runs on SIGINT (Ctrl-C) and SIGTERM (a scheduler's or Snakemake's kill).

Inside :func:`deferred` the two signals only set a flag, :func:`requested`; the run's loop polls
it after each unit of work (an MD window, an SLP step), writes its checkpoint at the next point
where the saved state continues exactly as the uninterrupted run would, and raises
:class:`Interrupted` (a :class:`KeyboardInterrupt`) with a message that says how to resume.
A second signal stops at once. Outside :func:`deferred`, within :func:`installed` (the command
line runs every command in it), both signals raise :class:`Interrupted` immediately, so atomic writes remove their
temporary files and the command exits with status 128 + signal number (130 for SIGINT, 143 for
SIGTERM). Handlers are installed only in the main thread of the process that installed them;
worker processes keep the default behaviour.
"""

from __future__ import annotations

import contextlib
import logging
import os
import signal
import threading

SIGNALS = (signal.SIGINT, signal.SIGTERM)

log = logging.getLogger("hardpack")

_pending: int | None = None
_depth = 0
_owner: int | None = None


class Interrupted(KeyboardInterrupt):
    """A run stopped by a signal; ``str(exc)`` says whether a checkpoint was written.

    Parameters
    ----------
    signum : int
        The signal number.
    message : str
        What happened and how to resume.
    """

    def __init__(self, signum: int, message: str):
        super().__init__(message)
        self.signum = signum

    @property
    def exit_code(self) -> int:
        return 128 + self.signum


def _name(signum: int) -> str:
    return signal.Signals(signum).name


def _handler(signum, frame) -> None:
    global _pending
    if os.getpid() != _owner:  # a forked child inherited the handler: behave as by default
        if signum == signal.SIGINT:
            raise KeyboardInterrupt
        signal.signal(signum, signal.SIG_DFL)
        os.kill(os.getpid(), signum)
        return
    if _depth and _pending is None:
        _pending = signum
        log.warning("%s received: stopping at the next checkpoint (send it again to stop at once)",
                    _name(signum))
        return
    raise Interrupted(signum, f"stopped by {_name(signum)}")


@contextlib.contextmanager
def installed():
    """Within, SIGINT and SIGTERM raise :class:`Interrupted` (main thread only; the previous
    handlers are restored on exit).

    Yields
    ------
    None
    """
    global _owner
    previous = {}
    if threading.current_thread() is threading.main_thread():
        previous = {sig: signal.getsignal(sig) for sig in SIGNALS}
        _owner = os.getpid()
        for sig in SIGNALS:
            signal.signal(sig, _handler)
    try:
        yield
    finally:
        for sig, handler in previous.items():
            if handler is not None:
                signal.signal(sig, handler)


def requested() -> int | None:
    """The signal received inside :func:`deferred`, or None.

    Returns
    -------
    int or None
        The signal number.
    """
    return _pending


@contextlib.contextmanager
def deferred():
    """Within, SIGINT and SIGTERM set :func:`requested` instead of stopping the run at once.

    Yields
    ------
    None
    """
    global _depth, _pending, _owner
    previous = {}
    if _depth == 0 and threading.current_thread() is threading.main_thread():
        previous = {sig: signal.getsignal(sig) for sig in SIGNALS}
        _owner = os.getpid()
        for sig in SIGNALS:
            signal.signal(sig, _handler)
    _depth += 1
    try:
        yield
    finally:
        _depth -= 1
        if _depth == 0:
            _pending = None
        for sig, handler in previous.items():
            if handler is not None:
                signal.signal(sig, handler)


def stop(checkpoint, where: str) -> Interrupted:
    """The exception a polling loop raises after writing ``checkpoint`` (None: no checkpoint).

    Parameters
    ----------
    checkpoint : str or os.PathLike or None
        The checkpoint written.
    where : str
        Where the run stopped, for the message.

    Returns
    -------
    Interrupted
        The exception.
    """
    signum = _pending if _pending is not None else signal.SIGINT
    if checkpoint is None:
        text = (f"stopped by {_name(signum)} at {where}; no checkpoint file was given, so the run "
                "starts from the beginning when started again")
    else:
        text = (f"stopped by {_name(signum)} at {where}; checkpoint written to {checkpoint}: start "
                "the same run again (same arguments and checkpoint) to resume")
    return Interrupted(signum, text)
