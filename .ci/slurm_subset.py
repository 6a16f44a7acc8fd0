"""CI helper: prepare a SLURM run of the smoke DAG in which every rule runs at least once.

The whole smoke DAG through SLURM costs about 6 s of Snakemake start-up per SLURM job on top of
the work, which made CI too long. Instead, the SLURM directory starts from a copy of the local
run's results, from which this script deletes the validation outputs and, for every rule of the
DAG, the outputs of one of its jobs (the first in `snakemake --summary`). It prints those files:
named as targets beside `all`, they make Snakemake run each rule once under SLURM, plus the jobs
downstream of the deleted files (combines, summaries, figures, the validation report and gate).
The SLURM validation dataset is then rebuilt from SLURM outputs and local ones, and must equal the
local dataset.

    python .ci/slurm_subset.py SUMMARY_TSV SLURM_DIR > targets.txt
"""

import csv
import shutil
import sys
from pathlib import Path


def one_output_per_rule(summary_tsv: str) -> dict[str, str]:
    """First output file of every rule in a `snakemake --summary` table (tab-separated)."""
    with open(summary_tsv, newline="") as fh:
        rows = list(csv.DictReader(fh, delimiter="\t"))
    if not rows or "rule" not in rows[0] or "output_file" not in rows[0]:
        raise SystemExit(f"{summary_tsv}: not a `snakemake --summary` table")
    first: dict[str, str] = {}
    for row in rows:
        first.setdefault(row["rule"], row["output_file"])
    return first


def main(summary_tsv: str, slurm_dir: str) -> None:
    root = Path(slurm_dir)
    picks = one_output_per_rule(summary_tsv)
    shutil.rmtree(root / "results" / "validation", ignore_errors=True)
    for rule, output in sorted(picks.items()):
        path = root / output
        if path.is_dir():
            shutil.rmtree(path)
        elif path.exists():
            path.unlink()
        print(f"slurm_subset: {rule}: {output}", file=sys.stderr)
    print(" ".join(sorted(set(picks.values()))))


if __name__ == "__main__":
    if len(sys.argv) != 3:
        raise SystemExit(__doc__)
    main(*sys.argv[1:])
