"""Lazy re-exports for a subpackage's ``__init__`` (PEP 562 module ``__getattr__``).

A subpackage re-exports its public names, but importing every module that defines them costs a
job that needs one of them the imports of all (numba kernels, scipy.sparse, the LP solvers): a
figure script that draws a reference curve of :mod:`hardpack.freeenergy.crystal` imported the
BCMD engine and the jamming tests with it, ~1 s of its start-up. With :func:`lazy_exports` a
name's module is imported on first access, and ``from hardpack.freeenergy import run_bcmd`` works
as before.
"""

from __future__ import annotations

import importlib
import sys


def lazy_exports(package: str, exports: dict[str, tuple[str, ...]]):
    """Module ``__getattr__`` and ``__dir__`` of a package whose public names are imported from
    their modules on first access.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    exports : dict of str to tuple of str
        For each module of the package (name relative to the package), the public names it
        provides.

    Returns
    -------
    getattr_ : callable
        The package's ``__getattr__``: imports the module of a public name and binds the name in
        the package, so the next access is a plain attribute lookup.
    dir_ : callable
        The package's ``__dir__``: the module's own attributes and the public names.

    Raises
    ------
    ValueError
        If a public name is also the name of a module of the package: once that module is
        imported, the import system binds its name in the package to the module, which would
        then shadow the public name (re-export such names eagerly instead).
    """
    where = {name: module for module, names in exports.items() for name in names}
    clashes = sorted(set(where) & set(exports))
    if clashes:
        raise ValueError(f"{package}: public names that are also module names cannot be lazy: {clashes}")

    def getattr_(name: str):
        module = where.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f"{package}.{module}"), name)
        setattr(sys.modules[package], name, value)
        return value

    def dir_() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(where))

    return getattr_, dir_
