"""Predicted wall time of the study on a cluster of C cores, from the DAG and the job records.

Reads the DAG of the study (``snakemake -n --forceall``: every job with its rule, threads,
runtime limit and benchmark file; ``snakemake --d3dag``: the dependencies), gives each job a
duration, and prints

- the work (core-hours) and the critical path (the longest chain of dependent jobs: no number of
  cores finishes sooner),
- for each core count, a list-scheduling estimate: whenever cores are free, start the ready job
  with the longest path to the end of the DAG (largest critical-path priority first), each job on
  ``threads`` cores; plus a fixed per-job overhead of the cluster (submission, start-up,
  Snakemake's status checks).

A job's duration is its wall time recorded by Snakemake (``s`` of its ``benchmark:`` file, under
any of the ``--records`` directories) when there is one; otherwise the expected minutes of the
cost model of ``workflow/rules/common.smk`` (docs/cluster.md), recovered from the job's runtime
limit: (runtime - RUNTIME_SLACK) / RUNTIME_SAFETY. Assumptions: every job runs at the speed of
one core of the 2-core development machine (where the records come from, with the load of the
time); cores are interchangeable, a job's threads all on one node; no queue wait beyond the
per-job overhead; a job runs once (no time-limit retries).

    python benchmarks/cluster_prediction.py [--configfile config/config.yaml] \
        [--records /path/to/study ...] [--cores 64 512] [--overhead 20]
"""

from __future__ import annotations

import argparse
import csv
import heapq
import json
import re
import subprocess
import sys
from collections import Counter, defaultdict
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


@dataclass
class Job:
    jobid: int
    rule: str
    threads: int = 1
    runtime: float | None = None  # minutes, the limit at attempt 1
    benchmark: str | None = None
    minutes: float = 0.0
    source: str = "model"
    children: list[int] = field(default_factory=list)
    parents: list[int] = field(default_factory=list)


def model_constants(common: Path) -> tuple[float, float]:
    """(RUNTIME_SAFETY, RUNTIME_SLACK) of the cost model."""
    text = common.read_text()
    safety = float(re.search(r"^RUNTIME_SAFETY = ([0-9.]+)", text, re.M).group(1))
    slack = float(re.search(r"^RUNTIME_SLACK = ([0-9.]+)", text, re.M).group(1))
    return safety, slack


def snakemake(args: list[str], cwd: Path) -> tuple[str, str]:
    """stdout and stderr of a snakemake command (without any profile)."""
    done = subprocess.run(["snakemake", "--workflow-profile", "none", *args], cwd=cwd, capture_output=True,
                          text=True)
    if done.returncode != 0:
        sys.exit(f"snakemake {' '.join(args)} failed:\n{done.stderr[-3000:]}")
    return done.stdout, done.stderr


def parse_jobs(dry_run: str) -> dict[int, Job]:
    """The jobs of a dry run (a group job's members are listed indented)."""
    jobs: dict[int, Job] = {}
    for block in re.split(r"\n(?=\s*(?:local)?rule \w+:)", dry_run):
        head = re.match(r"\s*(?:local)?rule (\w+):", block)
        jobid = re.search(r"^\s*jobid: (\d+)", block, re.M)
        if not head or not jobid:
            continue
        job = Job(int(jobid.group(1)), head.group(1))
        if threads := re.search(r"^\s*threads: (\d+)", block, re.M):
            job.threads = int(threads.group(1))
        if runtime := re.search(r"^\s*resources: .*\bruntime=(\d+)", block, re.M):
            job.runtime = float(runtime.group(1))
        if bench := re.search(r"^\s*benchmark: (\S+)", block, re.M):
            job.benchmark = bench.group(1)
        jobs[job.jobid] = job
    return jobs


def add_edges(jobs: dict[int, Job], d3dag: str) -> None:
    dag = json.loads(d3dag)
    for node in dag["nodes"]:
        jobid, rule = node["value"]["jobid"], node["value"]["rule"]
        if jobid not in jobs or jobs[jobid].rule != rule:
            sys.exit(f"the DAG's job {jobid} ({rule}) is not that of the dry run: job ids differ between the runs")
    for edge in dag["edges"]:
        jobs[edge["u"]].children.append(edge["v"])
        jobs[edge["v"]].parents.append(edge["u"])


def recorded_seconds(path: Path) -> float | None:
    try:
        with path.open(newline="") as handle:
            rows = list(csv.DictReader(handle, delimiter="\t"))
    except OSError:
        return None
    return sum(float(r["s"]) for r in rows) / len(rows) if rows else None


def assign_durations(jobs: dict[int, Job], records: list[Path], safety: float, slack: float) -> None:
    for job in jobs.values():
        if job.rule == "all":
            continue
        for root in records:
            if job.benchmark and (seconds := recorded_seconds(root / job.benchmark)) is not None:
                job.minutes, job.source = seconds / 60, "record"
                break
        else:
            job.minutes = max(0.0, ((job.runtime or slack) - slack) / safety)


def bottom_levels(jobs: dict[int, Job], overhead: float) -> dict[int, float]:
    """Minutes from a job's start to the end of the DAG along its longest chain of dependents."""
    level: dict[int, float] = {}

    def visit(jobid: int) -> float:
        if jobid not in level:
            job = jobs[jobid]
            level[jobid] = job.minutes + overhead + max((visit(c) for c in job.children), default=0.0)
        return level[jobid]

    sys.setrecursionlimit(max(10000, 4 * len(jobs)))
    for jobid in jobs:
        visit(jobid)
    return level


def list_schedule(jobs: dict[int, Job], cores: int, priority: dict[int, float], overhead: float) -> float:
    """Makespan (minutes) of greedy list scheduling on ``cores`` cores, highest priority first."""
    waiting = {j: len(job.parents) for j, job in jobs.items()}
    ready = [(-priority[j], j) for j, n in waiting.items() if n == 0]
    heapq.heapify(ready)
    running: list[tuple[float, int]] = []
    free, now = cores, 0.0
    while ready or running:
        deferred = []
        while ready:
            prio, j = heapq.heappop(ready)
            need = min(jobs[j].threads, cores)
            if need <= free:
                free -= need
                heapq.heappush(running, (now + jobs[j].minutes + overhead, j))
            else:
                deferred.append((prio, j))
        for item in deferred:
            heapq.heappush(ready, item)
        now, j = heapq.heappop(running)
        free += min(jobs[j].threads, cores)
        for c in jobs[j].children:
            waiting[c] -= 1
            if waiting[c] == 0:
                heapq.heappush(ready, (-priority[c], c))
    return now


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--configfile", default="config/config.yaml")
    parser.add_argument("--records", type=Path, nargs="*", default=[],
                        help="workflow directories whose results/benchmarks/ hold job records")
    parser.add_argument("--cores", type=int, nargs="*", default=[64, 512])
    parser.add_argument("--overhead", type=float, default=20.0,
                        help="seconds of cluster overhead per job (submission, start-up, status checks)")
    args = parser.parse_args()
    overhead = args.overhead / 60
    common = ["--forceall", "--configfile", str(ROOT / args.configfile)]
    jobs = parse_jobs("".join(snakemake(["-n", "--cores", "1024", *common], ROOT)))
    add_edges(jobs, snakemake(["--d3dag", *common], ROOT)[0])
    safety, slack = model_constants(ROOT / "workflow" / "rules" / "common.smk")
    assign_durations(jobs, args.records, safety, slack)
    jobs.pop(next(j for j, job in jobs.items() if job.rule == "all"), None)
    for job in jobs.values():
        job.children = [c for c in job.children if c in jobs]
        job.parents = [p for p in job.parents if p in jobs]

    sources = Counter(job.source for job in jobs.values())
    per_rule: dict[str, list[Job]] = defaultdict(list)
    for job in jobs.values():
        per_rule[job.rule].append(job)
    print(f"{len(jobs)} jobs: {sources['record']} with a record, {sources['model']} from the cost model")
    print(f"{'rule':24s} {'jobs':>5s} {'records':>7s} {'core-h':>7s} {'longest (min)':>14s}")
    for rule, rjobs in sorted(per_rule.items(), key=lambda kv: -sum(j.minutes * j.threads for j in kv[1])):
        print(f"{rule:24s} {len(rjobs):5d} {sum(j.source == 'record' for j in rjobs):7d} "
              f"{sum(j.minutes * j.threads for j in rjobs) / 60:7.2f} {max(j.minutes for j in rjobs):14.1f}")
    work = sum(job.minutes * job.threads for job in jobs.values())
    level = bottom_levels(jobs, overhead)
    chain, j = [], max((j for j, job in jobs.items() if not job.parents), key=level.get)
    while True:
        chain.append(j)
        if not jobs[j].children:
            break
        j = max(jobs[j].children, key=level.get)
    print(f"work: {work / 60:.1f} core-hours; critical path: {level[chain[0]]:.0f} min "
          f"({' -> '.join(f'{jobs[c].rule} {jobs[c].minutes:.0f}' for c in chain)})")
    for cores in args.cores:
        makespan = list_schedule(jobs, cores, level, overhead)
        bound = max(level[chain[0]], work / cores)
        print(f"{cores:4d} cores: list schedule {makespan / 60:.2f} h (lower bound max(critical path, "
              f"work / cores) = {bound / 60:.2f} h)")


if __name__ == "__main__":
    main()
