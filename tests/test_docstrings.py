"""Every public function and class of hardpack has numpydoc sections (the project standard:
numpydoc docstrings on public functions): "Parameters" when a function takes parameters,
"Returns" (or "Yields") when it returns a value, and for a class whose constructor takes
parameters "Parameters" or "Attributes". Checked: every name in a subpackage's ``__all__``, the
MD kernel's event loop, and every public module-level function and class of every public module
(:func:`public_modules`). Numba functions are checked through their Python source.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
import textwrap

import pytest
from numba import njit

import hardpack
from hardpack.md import _kernel as kernel


def python_function(obj):
    """The Python function of a plain or numba-compiled function, else None."""
    obj = getattr(obj, "py_func", obj)
    return obj if inspect.isfunction(obj) else None


def public_api() -> dict[str, object]:
    """Qualified name -> function or class, for every name in a subpackage's ``__all__``."""
    found = {}
    for info in pkgutil.iter_modules(hardpack.__path__):
        if not info.ispkg:
            continue
        module = importlib.import_module(f"hardpack.{info.name}")
        for name in getattr(module, "__all__", []):
            obj = getattr(module, name)
            if python_function(obj) is None and not inspect.isclass(obj):
                continue
            found[f"{obj.__module__}.{name}"] = obj
    found["hardpack.md._kernel.run_events"] = kernel.run_events
    return found


API = public_api()


def returns_value(func) -> bool:
    """Whether the function's own body (not nested definitions) returns a value or yields."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(func))).body[0]
    if isinstance(tree.returns, ast.Constant) and tree.returns.value in (None, "None"):
        return False
    todo = list(tree.body)
    while todo:
        node = todo.pop()
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef, ast.Lambda)):
            continue
        if isinstance(node, (ast.Yield, ast.YieldFrom)):
            return True
        if isinstance(node, ast.Return) and node.value is not None and not (
                isinstance(node.value, ast.Constant) and node.value.value is None):
            return True
        todo.extend(ast.iter_child_nodes(node))
    return False


def has_section(doc: str, *titles: str) -> bool:
    return any(f"{t}\n{'-' * len(t)}" in doc for t in titles)


def missing_sections(obj) -> list[str]:
    """The numpydoc sections ``obj`` (function or class) needs and lacks."""
    doc = inspect.cleandoc(obj.__doc__ or "")
    if inspect.isclass(obj):
        init = obj.__dict__.get("__init__")
        takes = init is not None and len(inspect.signature(init).parameters) > 1
        return ["Parameters"] if takes and not has_section(doc, "Parameters", "Attributes") else []
    func = python_function(obj)
    missing = []
    if inspect.signature(func).parameters and not has_section(doc, "Parameters"):
        missing.append("Parameters")
    if returns_value(func) and not has_section(doc, "Returns", "Yields"):
        missing.append("Returns")
    return missing


def test_the_public_api_is_found():
    assert len(API) >= 90
    for name in ("hardpack.jamming.verify.verify", "hardpack.md._kernel.run_events",
                 "hardpack.events.roots.pair_time", "hardpack.geometry.packing.Packing",
                 "hardpack.jamming.contacts.contact_network"):
        assert name in API
    assert "hardpack.jamming.second_order.EllipsoidJammingResult" in API


@pytest.mark.parametrize("name", sorted(API))
def test_numpydoc_sections(name):
    missing = missing_sections(API[name])
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

    def no_value(x):
        """Summary; x: a number."""
        def inner():
            return x
        if x:
            return
        inner()

    def no_parameters():
        """Summary.

        Yields
        ------
        int
            One.
        """
        yield 1

    class Record:
        """Summary.

        Attributes
        ----------
        x : int
            A number.
        """

        def __init__(self, x):
            self.x = x

    class Bare:
        """Summary."""

        def __init__(self, x):
            self.x = x

    class NoArguments:
        """Summary."""

    assert missing_sections(documented) == []
    assert missing_sections(njit(documented)) == []
    assert missing_sections(undocumented) == ["Parameters", "Returns"]
    assert missing_sections(njit(undocumented)) == ["Parameters", "Returns"]
    assert missing_sections(no_value) == ["Parameters"]
    assert missing_sections(no_parameters) == []
    assert missing_sections(Record) == []
    assert missing_sections(Bare) == ["Parameters"]
    assert missing_sections(NoArguments) == []


def public_modules() -> list[str]:
    """Every module of hardpack whose dotted name has no part starting with "_"."""
    return ["hardpack"] + [info.name for info in pkgutil.walk_packages(hardpack.__path__, "hardpack.")
                           if not any(part.startswith("_") for part in info.name.split("."))]


def audit(module_names) -> list[tuple[str, str, list[str]]]:
    """(module, name, missing sections) of every public module-level function and class defined
    in the named modules."""
    rows = []
    for module_name in module_names:
        module = importlib.import_module(module_name)
        for name, obj in vars(module).items():
            if name.startswith("_") or getattr(obj, "__module__", None) != module_name:
                continue
            if inspect.isclass(obj) or python_function(obj) is not None:
                missing = missing_sections(obj)
                if missing:
                    rows.append((module_name, name, missing))
    return rows


#: every public module: each public function and class in it is documented
DOCUMENTED_MODULES = tuple(public_modules())


def test_every_subpackage_is_audited():
    subpackages = {info.name for info in pkgutil.iter_modules(hardpack.__path__)
                   if info.ispkg and not info.name.startswith("_")}
    audited = {name.split(".")[1] for name in DOCUMENTED_MODULES if name.count(".") >= 1}
    assert subpackages <= audited
    assert {"hardpack", "hardpack.cli", "hardpack.md.engine", "hardpack.geometry.neighbours.grid"} <= set(
        DOCUMENTED_MODULES)


@pytest.mark.parametrize("module_name", DOCUMENTED_MODULES)
def test_documented_modules(module_name):
    rows = audit([module_name])
    assert not rows, f"public names without numpydoc sections: {rows}"


if __name__ == "__main__":  # the audit of every public module: python tests/test_docstrings.py [-v]
    import collections
    import sys

    rows = audit(public_modules())
    per_subpackage = collections.Counter(module.split(".")[1] if "." in module else module
                                         for module, _, _ in rows)
    for subpackage, count in sorted(per_subpackage.items()):
        print(f"{subpackage:14s} {count}")
    print(f"{'total':14s} {len(rows)}")
    if "-v" in sys.argv:
        for row in rows:
            print(*row)
