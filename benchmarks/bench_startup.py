"""Benchmark of a pipeline job's start-up: the fixed cost every Snakemake job pays before its work.

Most jobs of the smoke DAG are small, so their start-up (the interpreter, numpy, xarray with
pandas, numba and numba's first dispatch of a cached kernel) is most of the DAG's CPU time. This
times a ladder of commands, each adding one layer, in fresh processes. Prints a table; never part
of the test suite.

    python benchmarks/bench_startup.py             # 7 runs per command
    python benchmarks/bench_startup.py --runs 15

Each command runs once unmeasured first (bytecode and numba caches written), then ``--runs`` times;
medians of wall-clock and CPU time (user + system of the finished child) are printed. Python's
bytecode cache must be on, as in CI: with PYTHONDONTWRITEBYTECODE set, every process compiles the
sources of changed modules again, so the script unsets it for its children.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def timed(command: list[str], env: dict[str, str]) -> tuple[float, float]:
    """(wall seconds, CPU seconds) of one run of ``command``, which must succeed."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(command, env=env, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def init_command(workdir: Path, seed: int) -> list[str]:
    """``hardpack init`` of 64 spheres (RSA at phi = 0.2) into ``workdir/seed<seed>.nc``."""
    return [sys.executable, "-m", "hardpack.cli", "-q", "init", "--n", "64", "--d", "3", "--phi", "0.2",
            "--seed", str(seed), "--out", str(workdir / f"seed{seed}.nc")]


def ladder(workdir: Path) -> list[tuple[str, list[str]]]:
    """The commands timed, each one layer above the previous."""
    py = sys.executable
    seeds = [workdir / f"seed{s}.nc" for s in (1, 2)]
    return [
        ("python (interpreter)", [py, "-c", "pass"]),
        ("+ numpy", [py, "-c", "import numpy"]),
        ("+ xarray, pandas", [py, "-c", "import xarray"]),
        ("+ numba", [py, "-c", "import xarray, numba"]),
        ("hardpack --help", [py, "-m", "hardpack.cli", "--help"]),
        ("hardpack combine (2 files, no numba)",
         [py, "-m", "hardpack.cli", "-q", "combine", *map(str, seeds), "--index", "seed",
          "--out", str(workdir / "combined.nc")]),
        ("hardpack init (RSA, N = 64: numba's first dispatch)", init_command(workdir, 3)),
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7, help="measured runs per command (default 7)")
    args = parser.parse_args()
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    with tempfile.TemporaryDirectory() as tmp:
        workdir = Path(tmp)
        for seed in (1, 2):  # the inputs of the combine
            subprocess.run(init_command(workdir, seed), env=env, check=True)
        print(f"job start-up, {args.runs} runs per command (medians), {os.cpu_count()} CPUs, "
              f"load average {os.getloadavg()[0]:.1f}")
        print("| command | wall s | CPU s |")
        print("|---|---|---|")
        for label, command in ladder(workdir):
            timed(command, env)
            runs = [timed(command, env) for _ in range(args.runs)]
            wall = statistics.median(r[0] for r in runs)
            cpu = statistics.median(r[1] for r in runs)
            print(f"| {label} | {wall:.2f} | {cpu:.2f} |")


if __name__ == "__main__":
    main()
