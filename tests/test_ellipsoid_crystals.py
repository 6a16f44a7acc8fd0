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


# ------------------------------------------------------------- the family of Fig. 8.2 and its rows
def test_laminate_family_follows_fig_8_2():
    """Fig. 8.2: FCC at alpha = 1, the maximum 0.770732 with 14 contacts at sqrt(3), the unstretched
    laminate falling beyond it with 10 contacts (2 along the long axis, where L = 2 alpha, plus 8
    across layers), and the stretched one keeping 0.770732 and 14 contacts."""
    from hardpack.geometry.ellipsoid_crystals import laminate_family

    ds = laminate_family([1.0, 1.5, DENSEST_ALPHA, 2.0, 3.0])
    phi = ds["phi_laminate"].values
    assert phi[0] == pytest.approx(FCC, rel=1e-12)
    assert phi[2] == pytest.approx(0.770732, abs=5e-7)
    assert np.argmax(phi) == 2 and phi[3] < phi[2] and phi[4] < phi[3]
    assert ds["contacts_laminate"].values.tolist() == [12, 12, 14, 10, 10]
    assert ds["contacts_densest"].values.tolist() == [12, 12, 14, 14, 14]
    assert np.allclose(ds["phi_densest"].values[2:], 0.770732, atol=5e-7)
    assert ds["stretch"].values[4] == pytest.approx(2.4842, abs=5e-5)  # Fig. 8.3 caption
    assert ds["overlap_densest"].max() < 1e-9 and ds["overlap_laminate"].max() < 1e-9


def test_laminate_family_refuses_bad_aspect_ratios():
    from hardpack.geometry.ellipsoid_crystals import laminate_family, stretch_for

    for bad in ([], [0.5], [1.0, np.nan]):
        with pytest.raises(InvalidInputError, match="alphas must be finite numbers >= 1"):
            laminate_family(bad)
    with pytest.raises(InvalidInputError, match=">= sqrt"):
        stretch_for(1.5)


def test_crystal_rows_pass_fail_and_na():
    from hardpack.geometry.ellipsoid_crystals import laminate_family
    from hardpack.validation.ellipsoids import crystal_rows

    ds = laminate_family([1.0, DENSEST_ALPHA, 3.0])
    assert [r.status for r in crystal_rows([ds])] == ["pass"] * 4
    bent = ds.copy(deep=True)
    bent["phi_laminate"].values[1] += 1e-6  # one unit of the sixth printed digit off
    assert crystal_rows([bent])[0].status == "fail"
    assert [r.status for r in crystal_rows([laminate_family([1.0, 1.5])])] == ["n/a"] * 4


def test_laminate_command_writes_the_family_with_sqrt3_and_refuses_bad_input(tmp_path, capsys):
    from hardpack.cli import main
    from hardpack.io import load_dataset

    out = tmp_path / "family.nc"
    assert main(["laminate", "--alpha-max", "2.5", "--alpha-step", "0.5", "--out", str(out)]) == 0
    ds = load_dataset(out)
    assert ds["alpha"].values.tolist() == pytest.approx([1.0, 1.5, DENSEST_ALPHA, 2.0, 2.5])
    assert "git_commit" in ds.attrs or "hardpack_version" in ds.attrs
    assert main(["laminate", "--alpha-step", "0", "--out", str(out)]) != 0
    assert "--alpha-step must be a positive number" in capsys.readouterr().err


def test_laminate_figure_renders():
    from hardpack.geometry.ellipsoid_crystals import laminate_family
    from hardpack.plots.ellipsoids import plot_laminate_family

    fig = plot_laminate_family(laminate_family([1.0, 1.5, DENSEST_ALPHA, 2.0]))
    ax = fig.axes[0]
    assert ax.get_xscale() == "log" and len(ax.lines) >= 3
