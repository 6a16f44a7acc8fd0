"""The SLP size ascent (:mod:`hardpack.jamming.ascent`), an independent check of second-order verdicts.

Exact cases, the ellipse traps of Donev 2006, Fig. 5.5 (built in test_jamming_ellipsoids):
- the second-order flexible variant (normals meeting at I = (0, 0.5)): turned about I by theta and
  ascended, the ellipses grow by the second-order amount the stiffness predicts. Every LP step
  moves the mobile ellipse further along the mode by its trust radius, so the total turn is
  theta (1 + sum_k shrink^k), and the relative size gain is ds = -lambda theta_tot^2 (1 + |I|^2) /
  (2 sum_c F_c b_c). That follows from LP duality with the unique self-stress F (A F = 0, F > 0);
  b_c = 2 / s_c is the gap's rate under growth.
- Fig. 5.5 itself (jammed at second order): the same moves never end denser than the start.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_jamming_ellipsoids import FROZEN, _x_axis_trap, _y_axis_trap, trap

from hardpack.errors import InvalidInputError
from hardpack.geometry.boundaries import SphericalContainer
from hardpack.geometry.neighbours.pairs import wrapped_positions
from hardpack.geometry.packing import Packing
from hardpack.geometry.shapes import Ellipsoids
from hardpack.jamming import ascent as ascent_module
from hardpack.jamming.ascent import ASCENT_SHRINK, ASCENT_STEPS, ascend, confirm_unjamming
from hardpack.jamming.ellipsoids import ellipsoid_contacts
from hardpack.jamming.refine import displaced
from hardpack.jamming.result import Verdict
from hardpack.jamming.second_order import verify_ellipsoids


def _turned_about(packing, point, theta):
    """The mobile ellipse (particle 0) turned by theta about ``point`` (the floppy mode of a trap)."""
    move = np.zeros((packing.n_particles, 3))
    move[0] = [theta * point[1], -theta * point[0], theta]  # v = w z x (c - I), c = 0 in the trap's frame
    return displaced(packing, wrapped_positions(packing) + move[:, :2], move[:, 2:], 1.0)


def _no_overlap(packing):
    near = ellipsoid_contacts(packing, 1e-2)
    return near.n_contacts == 0 or near.zeta.min() >= 0.0


@pytest.fixture(params=["highs-ds", "highs-ipm"])
def lp_method(request, monkeypatch):
    """Each exact case with both LP methods of the ascent: the dual simplex of small packings and
    the interior-point method of large ones (``ascent.IPM_ABOVE`` lowered below the trap's N)."""
    if request.param == "highs-ipm":
        monkeypatch.setattr(ascent_module, "IPM_ABOVE", 0)
    return request.param


@pytest.mark.parametrize("theta", [0.005, -0.01])
def test_gain_of_an_unjamming_rotation_is_the_second_order_prediction(theta, lp_method):
    params, point = _y_axis_trap(0.5)
    packing = trap(params)
    res = verify_ellipsoids(packing, frozen=FROZEN, local=False)
    c = res.collective
    assert res.verdict == Verdict.NOT_JAMMED and res.order == "second" and c.lambda_min < 0
    out = ascend(_turned_about(packing, point, theta), frozen=FROZEN, radius=abs(theta))
    assert out.lp_method == lp_method
    total = abs(theta) * (1.0 + (1.0 - ASCENT_SHRINK**ASCENT_STEPS) / (1.0 - ASCENT_SHRINK))
    rate = 2.0 / res.network.scale[res.contacts_used]
    ds = -c.lambda_min * total**2 * (1.0 + point @ point) / (2.0 * c.forces @ rate)
    gain = (out.phi - packing.phi) / packing.phi
    assert gain == pytest.approx((1.0 + ds) ** 2 - 1.0, rel=2e-3)
    assert _no_overlap(out.packing)
    assert np.abs(wrapped_positions(out.packing)[1:] - wrapped_positions(packing)[1:]).max() < 1e-12


@pytest.mark.parametrize("theta", [0.01, -0.01, 0.04])
def test_a_second_order_jammed_trap_does_not_grow(theta, lp_method):
    """Fig. 5.5: the rotation about I closes the contacts at second order; ascents end at the
    jamming point's density within the ascent's last radius squared."""
    params, point = _x_axis_trap(0.3)
    packing = trap(params)
    assert verify_ellipsoids(packing, frozen=FROZEN).verdict == Verdict.JAMMED
    out = ascend(_turned_about(packing, point, theta), frozen=FROZEN, radius=abs(theta))
    assert out.lp_method == lp_method
    assert (out.phi - packing.phi) / packing.phi < 1e-9
    assert _no_overlap(out.packing)


def test_confirm_unjamming_certifies_the_flexible_trap_and_refuses_a_jammed_one(lp_method):
    params, _ = _y_axis_trap(0.5)
    packing = trap(params)
    res = verify_ellipsoids(packing, frozen=FROZEN, local=False)
    found = confirm_unjamming(packing, res)
    assert found.confirmed and found.gain > 1e-4 and found.tried == 1 and found.amplitude == 0.03
    assert _no_overlap(found.packing)
    jammed_params, _ = _x_axis_trap(0.3)
    jammed = trap(jammed_params)
    with pytest.raises(InvalidInputError, match="no unjamming motion"):
        confirm_unjamming(jammed, verify_ellipsoids(jammed, frozen=FROZEN))
    with pytest.raises(InvalidInputError, match="amplitudes"):
        confirm_unjamming(packing, res, amplitudes=[0.0])


def test_bad_input_is_refused():
    params, _ = _y_axis_trap(0.5)
    packing = trap(params)
    with pytest.raises(InvalidInputError, match="radius"):
        ascend(packing, radius=0.0)
    with pytest.raises(InvalidInputError, match="steps"):
        ascend(packing, steps=0)
    with pytest.raises(InvalidInputError, match="frozen"):
        ascend(packing, frozen=[True])
    contained = Packing(np.array([[3.0, 3.0]]), lattice=6.0 * np.eye(2), allow_overlap=True,
                        shape=Ellipsoids(np.array([[2.0, 1.0]]), np.array([0.0])),
                        boundary=SphericalContainer((3.0, 3.0), 2.5))
    with pytest.raises(InvalidInputError, match="periodic"):
        ascend(contained)


# ------------------------------------------------------------------------------- deforming cell
def _free_of_overlaps(packing, margin=1e-9):
    """The packing shrunk uniformly until no pair overlaps (mu >= 1 + margin)."""
    near = ellipsoid_contacts(packing, 0.5)
    mu = float(np.sqrt(near.zeta + 1.0).min()) if near.n_contacts else 1.0
    factor = min(mu, 1.0) * (1.0 - margin)
    return displaced(packing, wrapped_positions(packing), np.zeros((packing.n_particles, 3)), factor)


@pytest.mark.parametrize("seed", [0, 2])
def test_a_random_lattice_of_one_spheroid_ascends_to_the_affine_fcc(seed):
    """One spheroid per cell is a lattice packing, the affine image of a sphere lattice. FCC is
    the only perfect lattice in 3D (Korkine & Zolotarev 1877), so it is the only local maximum of
    the lattice density, and every ascent of the deforming cell must end at pi / sqrt(18)
    (measured: 9 digits from phi 0.07-0.31), with 12 contacts (own images)."""
    rng = np.random.default_rng(seed)
    quaternion = rng.normal(size=4)
    start = Packing(np.full((1, 3), 0.1), lattice=4.0 * (np.eye(3) + 0.3 * rng.normal(size=(3, 3))),
                    shape=Ellipsoids(np.array([[np.sqrt(3.0), 1.0, 1.0]]), (quaternion / np.linalg.norm(quaternion))[None]),
                    allow_overlap=True)
    start = _free_of_overlaps(start, margin=1e-2)
    out = ascend(start, deform=True, radius=1e-2, rounds=100)
    assert start.phi < 0.35 and out.phi == pytest.approx(np.pi / np.sqrt(18.0), abs=1e-8)
    assert out.rounds < 100 and _no_overlap(out.packing)
    assert (ellipsoid_contacts(out.packing, 1e-6).counts() == 12).all()


def test_a_perturbed_laminate_ascends_back_to_it():
    """Donev's laminate at alpha = 1.5 (phi 0.753407, 12 contacts; Donev 2006, Sec. 8.2) is a
    strict local maximum of the density: moved by 1e-2 (centres, angles, cell strain) and shrunk
    free of overlaps (phi 0.71-0.725), the deforming ascent returns to it to 1e-8. In a fixed cell it
    cannot (the strain is needed)."""
    from hardpack.geometry.ellipsoid_crystals import laminate

    lam = laminate(1.5)
    rng = np.random.default_rng(0)
    strain = np.eye(3) + 0.01 * rng.normal(size=(3, 3))
    x = (wrapped_positions(lam) + 0.01 * rng.normal(size=(lam.n_particles, 3))) @ strain.T
    start = _free_of_overlaps(displaced(lam, x, 0.01 * rng.normal(size=(lam.n_particles, 3)), 1.0, strain @ lam.lattice))
    out = ascend(start, deform=True, radius=1e-2, rounds=50)
    assert start.phi < 0.73 and out.phi == pytest.approx(lam.phi, abs=1e-8)
    assert (ellipsoid_contacts(out.packing, 1e-6).counts() == 12).all()
    fixed = ascend(start, radius=1e-2, rounds=50)
    assert fixed.phi < lam.phi - 1e-3
