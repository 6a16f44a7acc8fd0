"""Job times of a pipeline run, per rule, from the benchmark files Snakemake writes.

Every rule of the workflow has a ``benchmark:`` directive: Snakemake writes the wall time, CPU
time and peak memory of each job it runs to ``results/benchmarks/{rule}/{wildcards}.tsv`` (or
``results/benchmarks/{rule}.tsv`` for a rule without wildcards), replacing the file when the job
runs again. This sums them per rule. The sum of wall times divided by the cores is the wall time
an ideally packed run on those cores would take. A job interrupted and started again (a run
resumed in segments with ``--rerun-incomplete``) counts with its last, successful attempt only:
the work of the earlier attempts up to their last checkpoint is not in the sum, and the work after
it was lost. A benchmark file stays when its job's outputs are deleted; it is counted until it is
deleted too.

    python benchmarks/pipeline_times.py [--root DIR] [--cores 2]

Job wall times include the waits on a machine shared with other work; CPU times do not. Snakemake
samples the CPU time of a job's processes (every 0.5 s for the first 15 s, then every 30 s), so the
CPU used after the last sample is missing: CPU times are lower bounds, by up to 30 s per job.
"""

from __future__ import annotations

import argparse
import csv
from collections import defaultdict
from pathlib import Path

#: where the workflow writes its benchmark files, below the workflow directory
BENCHMARKS = Path("results") / "benchmarks"


def read_benchmark(path: Path) -> tuple[float, float]:
    """(wall seconds, CPU seconds) of one benchmark file (the mean of its repeats)."""
    with path.open(newline="") as handle:
        rows = list(csv.DictReader(handle, delimiter="\t"))
    if not rows:
        raise ValueError(f"{path}: no measurement (an empty benchmark file)")
    wall = [float(row["s"]) for row in rows]
    cpu = [float(row["cpu_time"]) if row.get("cpu_time") not in (None, "", "NA", "-") else 0.0 for row in rows]
    return sum(wall) / len(wall), sum(cpu) / len(cpu)


def job_times(root: Path) -> dict[str, list[tuple[float, float]]]:
    """{rule: [(wall seconds, CPU seconds) of each job]} from the benchmark files under ``root``."""
    folder = root / BENCHMARKS
    per_rule: dict[str, list[tuple[float, float]]] = defaultdict(list)
    for path in sorted(folder.rglob("*.tsv")) if folder.is_dir() else ():
        rule = path.relative_to(folder).parts[0].removesuffix(".tsv")
        per_rule[rule].append(read_benchmark(path))
    return dict(per_rule)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", type=Path, default=Path("."), help="the workflow directory")
    parser.add_argument("--cores", type=int, default=2)
    args = parser.parse_args()
    per_rule = job_times(args.root)
    if not per_rule:
        raise SystemExit(f"no benchmark files under {args.root / BENCHMARKS}")
    wall = sum(w for jobs in per_rule.values() for w, _ in jobs)
    cpu = sum(c for jobs in per_rule.values() for _, c in jobs)
    print(f"{'rule':28s} {'jobs':>5s} {'wall (h)':>9s} {'CPU (h)':>8s} {'longest (min)':>14s}")
    for rule, jobs in sorted(per_rule.items(), key=lambda kv: -sum(w for w, _ in kv[1])):
        print(f"{rule:28s} {len(jobs):5d} {sum(w for w, _ in jobs) / 3600:9.2f} "
              f"{sum(c for _, c in jobs) / 3600:8.2f} {max(w for w, _ in jobs) / 60:14.1f}")
    n_jobs = sum(len(jobs) for jobs in per_rule.values())
    print(f"{n_jobs} jobs, {wall / 3600:.2f} job-hours of wall time ({cpu / 3600:.2f} CPU-hours); "
          f"on {args.cores} cores, ideally packed: {wall / 3600 / args.cores:.2f} h")


if __name__ == "__main__":
    main()
