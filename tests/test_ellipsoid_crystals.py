"""The laminate crystals of spheroids (Donev 2006, ch. 8, Sec. 8.2): density, contacts, stretching."""

import itertools
import math

import numpy as np
import pytest

from hardpack import InvalidInputError
from hardpack.geometry.contact import pw_contact
from hardpack.geometry.ellipsoid_crystals import (
    DENSEST_ALPHA,
    laminate,
    square_side,
    stretched_alpha,
    stretched_laminate,
)

FCC = math.pi / math.sqrt(18)


def contact_functions(packing, reach: int = 2) -> np.ndarray:
    """zeta of every particle with every other particle and periodic image ((N, ...) per particle)."""
    inverses = np.linalg.inv(packing.shape.shape_matrices())
    out = [[] for _ in range(packing.n_particles)]
    for i, j in itertools.product(range(packing.n_particles), repeat=2):
        for shift in itertools.product(range(-reach, reach + 1), repeat=3):
            if i == j and not any(shift):
                continue
            r = packing.positions[j] + packing.lattice @ np.array(shift, float) - packing.positions[i]
            out[i].append(pw_contact(r, inverses[i], inverses[j], 0.5)[0])
    return np.array(out)


def test_alpha_one_is_fcc():
    p = laminate(1.0)
    assert p.phi == pytest.approx(FCC, rel=1e-12)
    zeta = contact_functions(p)
    assert (np.abs(zeta) < 1e-10).sum(axis=1).tolist() == [12] * 4
    assert zeta.min() > -1e-10


def test_densest_laminate_has_the_published_density_and_14_contacts():
    """Donev 2006, Sec. 8.2: phi = 0.770732 at alpha = sqrt(3), 14 contacts per particle."""
    p = laminate(DENSEST_ALPHA)
    assert p.phi == pytest.approx(0.770732, abs=5e-7)
    zeta = contact_functions(p)
    assert (np.abs(zeta) < 1e-9).sum(axis=1).tolist() == [14] * 4
    assert zeta.min() > -1e-9


@pytest.mark.parametrize("alpha", [1.2, 1.5, 1.7])
def test_generic_laminates_touch_12_neighbours_and_do_not_overlap(alpha):
    zeta = contact_functions(laminate(alpha))
    assert (np.abs(zeta) < 1e-9).sum(axis=1).tolist() == [12] * 4
    assert zeta.min() > -1e-9


def test_density_peaks_sharply_at_sqrt3():
    """Fig. 8.2: the laminate density rises from FCC, without a linear term, to its maximum at
    sqrt(3) and falls beyond it (where L = 2 alpha is fixed by the in-plane neighbours)."""
    alphas = np.linspace(1.0, 2.5, 61)
    phis = np.array([laminate(float(a)).phi for a in alphas])
    best = int(np.argmax(phis))
    assert abs(alphas[best] - DENSEST_ALPHA) <= 0.5 * (alphas[1] - alphas[0])
    assert np.all(np.diff(phis[: best + 1]) > 0) and np.all(np.diff(phis[best + 1:]) < 0)
    slope_at_one = (laminate(1.001).phi - FCC) / 0.001
    assert abs(slope_at_one) < 1e-3 * FCC  # second order in alpha - 1


def test_square_side_is_eq_8_1():
    assert square_side(1.0) == pytest.approx(2 * math.sqrt(2))
    assert square_side(DENSEST_ALPHA) == pytest.approx(2 * DENSEST_ALPHA)
    assert square_side(3.0) == 6.0


@pytest.mark.parametrize("s", [1.0, 1.7, 2.4842])
def test_stretching_keeps_density_and_contacts_and_follows_eq_8_3(s):
    p = stretched_laminate(s)
    assert p.phi == pytest.approx(laminate(DENSEST_ALPHA).phi, rel=1e-12)
    zeta = contact_functions(p, reach=3)
    assert (np.abs(zeta) < 1e-8).sum(axis=1).tolist() == [14] * 4
    # the stretch is in the layer plane: the semiaxis along z stays 1, the in-plane pair has the
    # aspect ratio of Eq. 8.3 (the z semiaxis can then be rescaled freely, e.g. to make spheroids)
    body_z = np.abs(p.shape.rotations()[:, :, 2])  # |z component| of each body axis
    for axes, along_z in zip(p.shape.semiaxes, body_z):
        k = int(np.argmax(along_z))
        assert along_z[k] == pytest.approx(1.0, abs=1e-12) and axes[k] == pytest.approx(1.0, rel=1e-12)
        in_plane = np.delete(axes, k)
        assert in_plane.max() / in_plane.min() == pytest.approx(stretched_alpha(s), rel=1e-10)


def test_published_stretch_gives_alpha_three():
    """Fig. 8.3: a stretch by 2.4842 gives alpha = 3 (printed to 5 digits)."""
    assert stretched_alpha(2.4842) == pytest.approx(3.0, abs=5e-4)
    assert stretched_alpha(1.0) == pytest.approx(DENSEST_ALPHA, rel=1e-14)


@pytest.mark.parametrize("bad", [0.5, float("nan"), "2"])
def test_bad_aspect_ratio_is_refused(bad):
    with pytest.raises(InvalidInputError, match="alpha"):
        laminate(bad)
