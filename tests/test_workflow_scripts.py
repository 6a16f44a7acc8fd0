"""Every workflow script imports names the library has: a script runs only inside the DAG, so a
renamed or lost function would otherwise fail only there."""

import ast
import importlib
import importlib.util
from pathlib import Path

import pytest

SCRIPTS = sorted((Path(__file__).resolve().parents[1] / "workflow" / "scripts").glob("*.py"))


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_script_imports_exist(script):
    tree = ast.parse(script.read_text())
    imported = [(node.module, alias.name) for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)
                and node.module and node.module.startswith("hardpack") for alias in node.names]
    for module, name in imported:
        found = hasattr(importlib.import_module(module), name)
        if not found:   # a submodule (from hardpack.plots import structure)
            found = importlib.util.find_spec(f"{module}.{name}") is not None
        assert found, f"{script.name}: {module} has no {name}"


def test_the_scripts_are_found():
    assert len(SCRIPTS) >= 10
