"""Rigorous jamming tests for sphere packings (Donev dissertation ch. 4): periodic cells, hard
walls and spherical containers (wall contacts with fixed wall points, sec. 4.4.3).

Entry point :func:`verify` -> :class:`JammingResult` (``.summary()``, ``.to_dataset()``).
Building blocks: :func:`contact_network`, :func:`rigidity_matrix` (scipy.sparse),
:func:`remove_rattlers` (iterative local test), :func:`ideal_test` (Algorithm 13),
:func:`sequential_test` (Algorithm 14), :func:`self_stress` and :func:`statics` (forces,
isostaticity, pressure). :mod:`hardpack.jamming.isostatic` solves the LPs exactly through the
self-stress space of rigid, nearly isostatic backbones (the common case for LS packings), HiGHS
(scipy ``linprog``) does the rest. CLI: ``hardpack verify`` (:mod:`hardpack.jamming.cli`).
Ellipses and ellipsoids (Donev 2006, ch. 5): :func:`verify_ellipsoids` (first- and second-order
tests, :mod:`hardpack.jamming.second_order`, on the contacts and stress matrix of
:mod:`hardpack.jamming.ellipsoids`), periodic, between flat hard walls or in a spherical container.
"""

from hardpack.jamming.contacts import ContactNetwork, contact_network
from hardpack.jamming.forces import self_stress, statics
from hardpack.jamming.ideal import ideal_test
from hardpack.jamming.rattlers import remove_rattlers
from hardpack.jamming.result import JammingResult
from hardpack.jamming.rigidity import rigidity_matrix, strain_pairs
from hardpack.jamming.second_order import EllipsoidJammingResult, verify_ellipsoids
from hardpack.jamming.sequential import sequential_test
from hardpack.jamming.verify import verify

__all__ = [
    "ContactNetwork",
    "EllipsoidJammingResult",
    "JammingResult",
    "contact_network",
    "ideal_test",
    "remove_rattlers",
    "rigidity_matrix",
    "self_stress",
    "sequential_test",
    "statics",
    "strain_pairs",
    "verify",
    "verify_ellipsoids",
]
