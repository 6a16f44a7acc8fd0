"""The validation report: every reproduced number beside its published target, and the gate.

Targets are data (``targets.yaml``, :mod:`hardpack.validation.targets`); rows judge a reproduced
value against a target (:mod:`hardpack.validation.rows`); one module per study builds its rows
from the pipeline's summaries.
"""

from hardpack.validation.rows import Row, evaluate, gate, to_dataset, to_markdown
from hardpack.validation.targets import Target, load_targets

__all__ = ["Row", "Target", "evaluate", "gate", "load_targets", "to_dataset", "to_markdown"]
