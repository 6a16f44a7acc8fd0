"""Lazy re-exports of the subpackages (hardpack._lazy): every public name resolves to the object
of its module, a module imports only what it needs, and a public name that is also a module name
is refused (the import system would shadow it)."""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest

from hardpack._lazy import lazy_exports

LAZY_PACKAGES = ["hardpack.freeenergy", "hardpack.geometry", "hardpack.slp", "hardpack.structure"]


@pytest.mark.parametrize("package", LAZY_PACKAGES)
def test_every_public_name_is_its_modules_object(package):
    pkg = importlib.import_module(package)
    for name in pkg.__all__:
        value = getattr(pkg, name)
        assert not isinstance(value, type(sys)), (package, name)  # an object, never a module
        assert name in dir(pkg)
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        getattr(pkg, "no_such_name")


@pytest.mark.parametrize(("module", "not_imported"), [
    ("hardpack.structure.containers", "hardpack.structure.analysis"),
    ("hardpack.freeenergy.crystal", "hardpack.freeenergy.bcmd"),
    ("hardpack.slp.ordermap", "hardpack.slp.driver"),
])
def test_a_module_does_not_import_its_siblings(module, not_imported):
    code = f"import sys, {module}; print({not_imported!r} in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"


def test_a_public_name_that_is_a_module_name_is_refused():
    with pytest.raises(ValueError, match=r"\['verify'\]"):
        lazy_exports("hardpack.jamming", {"verify": ("verify",), "forces": ("statics",)})
    getattr_, dir_ = lazy_exports("hardpack.jamming", {"forces": ("statics",)})
    from hardpack.jamming.forces import statics

    assert getattr_("statics") is statics and "statics" in dir_()
