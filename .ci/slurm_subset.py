"""CI helper: prepare a SLURM run of the smoke DAG in which every kind of job runs.

Each SLURM job costs about 6 s of Snakemake start-up on top of its work, and each generation of
cluster jobs waits on the executor's status checks, which back off while no job ends; so the SLURM
directory starts from a copy of the local run's results, from which this script deletes the
validation outputs and outputs whose jobs, with the jobs downstream of them, cover every kind of
job: each job group of the profile (setup, analyses, summaries, figures, validation: several tiny
jobs in one cluster job) and the compute rules, run by a shell command or by a script, one cluster
job each. It prints those files: named as targets beside `all`, they make Snakemake run those jobs
under SLURM, plus the jobs downstream of the deleted files. The SLURM validation dataset is then
rebuilt from SLURM outputs and local ones, and must equal the local dataset. (Every job's resources
under the profile are evaluated by a dry run of the whole DAG, .ci/slurm-smoke.)

The deleted files are chosen so that the rerun costs little: deleting one output reruns its job
and every job downstream of it, which covers their kinds too, so a greedy set cover over
Snakemake's records of the local run (.snakemake/metadata: each output's job, inputs, start and
end) picks them. Without records, the first output of a rule of each kind in `snakemake --summary`
is taken.

    python .ci/slurm_subset.py SUMMARY_TSV SLURM_DIR [METADATA_DIR [RULES_DIR]] > targets.txt
"""

import base64
import binascii
import csv
import json
import re
import shutil
import sys
from collections import defaultdict
from pathlib import Path


def rule_kinds(rules_dir: Path = Path("workflow/rules")) -> dict[str, str]:
    """The kind of every rule of the workflow: its job group, else "shell" or "script" (how a
    compute rule runs)."""
    kinds = {}
    for path in sorted(rules_dir.glob("*.smk")):
        for block in re.split(r"^(?=rule )", path.read_text(), flags=re.M)[1:]:
            name = re.match(r"rule (\w+):", block).group(1)
            group = re.search(r'^    group:\n        "(\w+)"', block, re.M)
            script = re.search(r"^    script:", block, re.M)
            kinds[name] = group.group(1) if group else ("script" if script else "shell")
    return kinds


def local_jobs(metadata_dir: Path) -> tuple[dict[str, tuple], dict[tuple, float], dict[str, set]]:
    """Snakemake's records of the local run: the job of each output file, each job's wall time,
    and the jobs that read each file."""
    job_of: dict[str, tuple] = {}
    seconds: dict[tuple, float] = {}
    readers: dict[str, set] = defaultdict(set)
    for record in metadata_dir.glob("*"):
        try:
            output = base64.urlsafe_b64decode(record.name).decode()
            meta = json.loads(record.read_text())
            job = (meta["rule"], meta.get("job_hash"), meta["endtime"])  # the same for all its outputs
            seconds[job] = float(meta["endtime"]) - float(meta["starttime"])
        except (OSError, ValueError, KeyError, TypeError, binascii.Error):
            continue  # a record split over directories (very long paths) or of another format
        job_of[output] = job
        for path in meta.get("input") or ():
            readers[path].add(job)
    return job_of, seconds, readers


def rerun_jobs(output: str, job_of, readers) -> set:
    """The local jobs that run again when ``output`` is deleted: its job and every job downstream
    of it (none when the job is not recorded)."""
    if output not in job_of:
        return set()
    outputs_of: dict[tuple, list] = defaultdict(list)
    for path, job in job_of.items():
        outputs_of[job].append(path)
    todo, seen = [job_of[output]], set()
    while todo:
        job = todo.pop()
        if job in seen:
            continue
        seen.add(job)
        for path in outputs_of[job]:
            todo.extend(readers.get(path, ()))
    return seen


def rerun_cost(output: str, job_of, seconds, readers) -> float:
    """Wall time in the local run of :func:`rerun_jobs` (infinite when the job is not recorded)."""
    jobs = rerun_jobs(output, job_of, readers)
    return sum(seconds[job] for job in jobs) if jobs else float("inf")


def one_output_per_kind(summary_tsv: str, metadata_dir: Path = Path(".snakemake/metadata"),
                        kinds: dict[str, str] | None = None) -> dict[str, str]:
    """Output files to delete so that a job of every kind of rule of a `snakemake --summary` table
    (tab-separated) runs again, at little cost: a greedy set cover over the recorded jobs (each
    deletion covers the kinds of the jobs it reruns, :func:`rerun_jobs`; the next one is the
    deletion with the least new job time per newly covered kind). ``kinds`` maps rules to their
    kinds (:func:`rule_kinds`); without it every rule is a kind of its own. Kinds without records
    get the first output of one of their rules. Returns {kind: file deleted for it}; a deletion
    listed under one kind may cover others."""
    with open(summary_tsv, newline="") as fh:
        rows = list(csv.DictReader(fh, delimiter="\t"))
    if not rows or "rule" not in rows[0] or "output_file" not in rows[0]:
        raise SystemExit(f"{summary_tsv}: not a `snakemake --summary` table")

    def kind(rule: str) -> str:
        return (kinds or {}).get(rule, rule)

    job_of, seconds, readers = local_jobs(metadata_dir)
    candidates = {row["output_file"]: rerun_jobs(row["output_file"], job_of, readers) for row in rows}
    uncovered = {kind(row["rule"]) for row in rows}
    picks: dict[str, str] = {}
    running: set = set()
    while uncovered:
        best = None
        for output, jobs in candidates.items():
            newly = {kind(job[0]) for job in jobs} & uncovered
            if newly:
                price = sum(seconds[job] for job in jobs - running) / len(newly)
                if best is None or price < best[0]:
                    best = (price, output, newly, jobs)
        if best is None:  # kinds whose jobs are all unrecorded
            break
        _, output, newly, jobs = best
        picks[sorted(newly)[0]] = output
        uncovered -= newly
        running |= jobs
    for row in rows:
        if kind(row["rule"]) in uncovered:
            picks.setdefault(kind(row["rule"]), row["output_file"])
    return picks


def main(summary_tsv: str, slurm_dir: str, metadata_dir: str = ".snakemake/metadata",
         rules_dir: str = "workflow/rules") -> None:
    root = Path(slurm_dir)
    picks = one_output_per_kind(summary_tsv, Path(metadata_dir), rule_kinds(Path(rules_dir)))
    shutil.rmtree(root / "results" / "validation", ignore_errors=True)
    for kind, output in sorted(picks.items()):
        path = root / output
        if path.is_dir():
            shutil.rmtree(path)
        elif path.exists():
            path.unlink()
        print(f"slurm_subset: {kind}: {output}", file=sys.stderr)
    print(" ".join(sorted(set(picks.values()))))


if __name__ == "__main__":
    if len(sys.argv) not in (3, 4, 5):
        raise SystemExit(__doc__)
    main(*sys.argv[1:])
