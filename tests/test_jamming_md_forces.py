"""LP contact forces vs the MD's time-averaged collision forces.

An isostatic backbone has a unique self-stress, so the LP forces and the MD forces must agree
contact by contact after one fitted factor, and the virial of the scaled LP forces must equal the
MD collisional pressure. Tolerances: 2 % on the pressure ratio (the MD average over 10 windows of
~N collisions per particle each has a statistical error of about 1 / sqrt(collisions per contact),
~1 %) and 15 % on the per-contact RMS difference (single contacts carry fewer collisions).
"""

import numpy as np
import pytest

from hardpack.distributions import monodisperse
from hardpack.initial import random_packing
from hardpack.jamming import verify
from hardpack.jamming.md_forces import compare_md_forces
from hardpack.md import StopCriteria, compress


@pytest.mark.slow
def test_lp_forces_match_md_forces_of_an_isostatic_ls_packing():
    """Seeds are tried until one gives an isostatic backbone (most do at this rate; a packing a
    contact short has no self-stress to compare); the first isostatic one must match."""
    for seed in (4, 5, 6):
        start = random_packing(64, 3, monodisperse(), 0.2, seed=seed)
        run = compress(start, 0.02, seed, StopCriteria(max_pressure=1e12), final_growth_rate=1e-4,
                       switch_pressure=1e3, contact_forces=True)
        result = verify(run.packing)
        if not (result.forces.exists and result.statics.isostaticity_gap == 0):
            continue
        cmp = compare_md_forces(result.network, result.forces.forces,
                                result.network.among(~result.rattler), run.contacts)
        assert cmp.n_matched >= 0.95 * cmp.n_lp_contacts
        assert cmp.pressure_ratio == pytest.approx(1.0, abs=0.02)
        assert cmp.rms_relative < 0.15
        assert cmp.md_virial_fraction > 0.99  # rattlers carry (almost) no pressure
        break
    else:
        pytest.fail("no isostatic packing from three seeds")


def test_a_wrong_force_network_is_detected():
    """Same contacts, forces permuted: the fitted virial no longer matches the MD pressure."""
    import xarray as xr

    from hardpack.geometry.lattices import lattice_packing

    p = lattice_packing("fcc", (2, 2, 2))
    result = verify(p)
    net = result.network
    rng = np.random.default_rng(0)
    f_md = 1.0 + rng.random(net.n_contacts)  # an MD network that is not the uniform LP self-stress
    md = xr.Dataset({"md_contact_i": ("c", net.i), "md_contact_j": ("c", net.j),
                     "md_contact_shift": (("c", "dim"), net.shift),
                     "md_contact_force": (("c", "dim"), net.normal * f_md[:, None]),
                     "md_contact_virial": ("c", f_md * net.distance)})
    backbone = net.among(~result.rattler)
    same = compare_md_forces(net, f_md, backbone, md)
    assert same.pressure_ratio == pytest.approx(1.0, rel=1e-12) and same.rms_relative < 1e-12
    uniform = compare_md_forces(net, result.forces.forces, backbone, md)
    assert uniform.rms_relative > 0.1
