"""CI check: every job of a Snakemake run through the slurm profile ran as a SLURM job.

Reads Snakemake's log of the run (job stats, the submissions `Job ... has been submitted with
SLURM jobid N (log: .../slurm_logs/rule_<rule>/... or group_<group>_.../...)`, the members of each
group job) and the SLURM controller's log of the same time (`_slurm_rpc_submit_batch_job:
JobId=N`, `_job_complete: JobId=N WEXITSTATUS 0`; sacct needs slurmdbd, which the CI SLURM does not
run). Checks that each job of a compute rule was submitted as its own SLURM job, that the members
of the group jobs are the jobs of the grouped rules, and that SLURM accepted and completed (exit 0)
every submitted job.

    python .ci/slurm_jobs.py SNAKEMAKE_LOG SLURMCTLD_LOG_OF_THE_RUN
"""

import re
import sys
from collections import Counter


def job_stats(text: str) -> Counter:
    table = text.split("Job stats:", 1)[1].split("\n\n", 1)[0]
    rows = re.findall(r"^(\w+)\s+(\d+)$", table, re.M)
    return Counter({rule: int(n) for rule, n in rows if rule not in ("total", "all")})


def main(snakemake_log: str, slurmctld_log: str) -> None:
    text = open(snakemake_log).read()
    ctld = open(slurmctld_log).read()
    stats = job_stats(text)
    submitted_as = r"has been submitted with SLURM jobid (\d+) \(log: \S*/slurm_logs/(rule|group)_([^/]+)/"
    submissions = re.findall(submitted_as, text)
    single = Counter(name for _, kind, name in submissions if kind == "rule")
    groups = Counter(name.split("_")[0] for _, kind, name in submissions if kind == "group")
    # the members of a group job are the only jobs printed indented; messages of the executor
    # may be interleaved with a group's list, so the list is not parsed as one block
    members = Counter(re.findall(r"^    (?:local)?rule (\w+):$", text, re.M))
    problems = []
    for rule, n in stats.items():
        ran = single[rule] + members[rule]
        if ran != n:
            problems.append(f"rule {rule}: {n} jobs, {single[rule]} submitted alone and {members[rule]} in groups")
    for rule in set(single) & set(members):
        problems.append(f"rule {rule} ran both alone and in groups")
    submitted = set(re.findall(r"_slurm_rpc_submit_batch_job: JobId=(\d+)", ctld))
    completed = set(re.findall(r"_job_complete: JobId=(\d+) WEXITSTATUS 0", ctld))
    for jobid, kind, name in submissions:
        if jobid not in submitted:
            problems.append(f"SLURM job {jobid} ({kind} {name}) is not in the controller's log")
        elif jobid not in completed:
            problems.append(f"SLURM job {jobid} ({kind} {name}) did not complete with exit status 0")
    if problems:
        sys.exit("slurm jobs:\n  " + "\n  ".join(problems))
    per_rule = ", ".join(f"{r} {n}" for r, n in sorted(single.items()))
    per_group = ", ".join(f"{g} {n}" for g, n in sorted(groups.items()))
    print(f"{sum(stats.values())} Snakemake jobs ran as {len(submissions)} SLURM jobs, all completed with exit "
          f"status 0: {sum(single.values())} compute jobs one each ({per_rule}), "
          f"{sum(members.values())} tiny jobs in {sum(groups.values())} group jobs ({per_group})")


if __name__ == "__main__":
    main(*sys.argv[1:])
