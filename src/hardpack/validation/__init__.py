"""The validation report: published numbers beside reproduced ones (issue 9)."""

from hardpack.validation.rows import Row, to_dataset, to_markdown

__all__ = ["Row", "to_dataset", "to_markdown"]
