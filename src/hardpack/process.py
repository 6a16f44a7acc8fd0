"""The set-up of a process that runs one pipeline job and ends: the ``hardpack`` console script
(:func:`hardpack.cli.console_main`) and the Snakemake scripts of ``workflow/scripts``.

Imports and numba's first dispatch leave ~1.5e5 long-lived objects (155525 tracked after a
``hardpack init``), which Python's collector, at its default thresholds, traverses again and again
while they are made (3 full and 31 middle collections, 0.42 s of a 2.0 s run) and once more in
the interpreter's clean-up at exit (~0.9 s of a 3 s ``hardpack init``). :func:`job_process`
collects the young generation every GC_THRESHOLD allocations instead of 700 (reference cycles
are still freed: at most that many objects wait) and freezes every object at exit
(:func:`gc.freeze`), so that the clean-up does not traverse them. Per job (paired runs, CPU
time): ``hardpack init`` 3.09 -> 2.29 s, a smoke ``compress`` of 64 spheres 5.52 -> 4.25 s,
``combine`` 1.44 -> 1.08 s, with identical outputs. A program that calls hardpack in a process
of its own (tests, notebooks) keeps its collector as it is.
"""

from __future__ import annotations

import atexit
import gc
import logging

#: generation-0 threshold of the collector in a job process (Python's default 700)
GC_THRESHOLD = 100_000


def job_process(log_path=None) -> None:
    """Set up the current process to run one job and end: the collector as in the module
    docstring, and optionally logging at INFO level into a file.

    Parameters
    ----------
    log_path : str or os.PathLike, optional
        The job's log file (a Snakemake script's ``snakemake.log[0]``); None leaves logging to
        the caller (the console script configures its own).
    """
    gc.set_threshold(GC_THRESHOLD, *gc.get_threshold()[1:])
    atexit.register(gc.freeze)  # the job's files are written and closed by the time atexit runs
    if log_path is not None:
        logging.basicConfig(filename=log_path, level=logging.INFO)
