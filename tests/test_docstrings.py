"""Every public function of the subpackages (their ``__all__``) and the MD kernel's event loop
have numpydoc "Parameters" and "Returns" sections (the project standard: numpydoc docstrings on
public functions)."""

from __future__ import annotations

import importlib
import inspect
import pkgutil

import pytest

import hardpack
from hardpack.md import kernel

SECTIONS = ("Parameters\n----------", "Returns\n-------")


def public_functions() -> dict[str, object]:
    """Qualified name -> function, for every function in a subpackage's ``__all__``."""
    found = {}
    for info in pkgutil.iter_modules(hardpack.__path__):
        if not info.ispkg:
            continue
        module = importlib.import_module(f"hardpack.{info.name}")
        for name in getattr(module, "__all__", []):
            obj = getattr(module, name)
            if inspect.isfunction(obj):
                found[f"{obj.__module__}.{obj.__name__}"] = obj
    found["hardpack.md.kernel.run_events"] = kernel.run_events
    return found


FUNCTIONS = public_functions()


def missing_sections(func) -> list[str]:
    doc = inspect.cleandoc(func.__doc__ or "")
    return [s.splitlines()[0] for s in SECTIONS if s not in doc]


def test_the_public_api_is_found():
    assert len(FUNCTIONS) >= 60
    assert "hardpack.jamming.verify.verify" in FUNCTIONS
    assert "hardpack.md.kernel.run_events" in FUNCTIONS


@pytest.mark.parametrize("name", sorted(FUNCTIONS))
def test_numpydoc_sections(name):
    missing = missing_sections(FUNCTIONS[name])
    assert not missing, f"{name}: the docstring has no numpydoc section(s) {missing}"


def test_the_check_detects_a_missing_section():
    def documented(x):
        """Summary.

        Parameters
        ----------
        x : int
            A number.

        Returns
        -------
        int
            The same number.
        """
        return x

    def undocumented(x):
        """Summary; x: a number. Returns the same number."""
        return x

    assert missing_sections(documented) == []
    assert missing_sections(undocumented) == ["Parameters", "Returns"]
