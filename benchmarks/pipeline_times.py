"""Job times of a pipeline run, per rule, from the start and end times Snakemake records.

Snakemake keeps, for every output file, the start and end time of the job that wrote it
(`.snakemake/metadata/`, one JSON file per output, named by the output path in URL-safe
base64). This sums them per rule over the outputs that still exist, counting a job with
several outputs once. The sum of job times divided by the cores is the wall time an ideally
packed run on those cores would take. A job that was interrupted and started again (a run resumed
in segments with `--rerun-incomplete`) counts with its last attempt only: the work of the earlier
attempts up to their last checkpoint is not in the sum, and the work after it was lost.

    python benchmarks/pipeline_times.py [--root DIR] [--cores 2]

Job times are wall times: on a machine shared with other work they include the waits.
"""

from __future__ import annotations

import argparse
import base64
import json
from collections import defaultdict
from pathlib import Path


def job_times(root: Path) -> dict[str, list[float]]:
    """{rule: [seconds of each job]} for the jobs whose outputs exist under ``root``."""
    jobs: dict[tuple[str, float], float] = {}
    folder = root / ".snakemake" / "metadata"
    for record in folder.iterdir() if folder.is_dir() else ():
        name = record.name
        output = base64.urlsafe_b64decode(name + "=" * (-len(name) % 4)).decode()
        if not (root / output).exists():
            continue
        meta = json.loads(record.read_text())
        start, end = meta.get("starttime"), meta.get("endtime")
        if start is None or end is None or meta.get("incomplete"):
            continue
        key = (meta["rule"], end)  # the outputs of one job share its end time (their starts differ by ms)
        jobs[key] = max(jobs.get(key, 0.0), end - start)
    per_rule: dict[str, list[float]] = defaultdict(list)
    for (rule, _), seconds in jobs.items():
        per_rule[rule].append(seconds)
    return dict(per_rule)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", type=Path, default=Path("."), help="the workflow directory")
    parser.add_argument("--cores", type=int, default=2)
    args = parser.parse_args()
    per_rule = job_times(args.root)
    if not per_rule:
        raise SystemExit(f"no finished jobs recorded under {args.root / '.snakemake' / 'metadata'}")
    total = sum(sum(v) for v in per_rule.values())
    print(f"{'rule':28s} {'jobs':>5s} {'sum (h)':>8s} {'longest (min)':>14s}")
    for rule, times in sorted(per_rule.items(), key=lambda kv: -sum(kv[1])):
        print(f"{rule:28s} {len(times):5d} {sum(times) / 3600:8.2f} {max(times) / 60:14.1f}")
    jobs = sum(len(v) for v in per_rule.values())
    print(f"{jobs} jobs, {total / 3600:.2f} job-hours; on {args.cores} cores, ideally packed: "
          f"{total / 3600 / args.cores:.2f} h")


if __name__ == "__main__":
    main()
