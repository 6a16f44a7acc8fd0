"""LP contact forces against the time-averaged contact forces the MD measured.

Near jamming the collision impulses a pair exchanges, averaged over time, are the contact force of
the packing up to one common factor (Donev 2006, sec. 1.1 and Fig. 1.1; hardpack.md.contacts). The LP
self-stress of an isostatic backbone is unique up to the same factor, so the two force networks
must agree contact by contact once that factor is fitted:

    s = sum_c f_MD,c f_LP,c / sum_c f_LP,c^2        (least squares over matched backbone contacts)

and the virial of the scaled LP forces, p_LP V = (1/d) sum_c s f_LP,c |r_c|, must equal the MD's
collisional pressure p_MD V = (1/d) sum_pairs W_ij = (Z - 1) N kT (hardpack.md.contacts). Here
f_MD,c = F_ij . u_ij, the time-averaged force along the final contact normal. Contacts are matched
by (i, j, lattice shift) with i < j.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hardpack.jamming.contacts import ContactNetwork


@dataclass(frozen=True)
class ForceComparison:
    """Scale s, LP-virial / MD-collisional-pressure ratio, relative RMS force difference over the
    matched contacts (in units of the mean MD force), and the matching counts.

    Attributes
    ----------
    scale : float
        Least-squares factor s with s f_LP ~ f_MD.
    pressure_ratio : float
        LP virial s sum f |r| over the MD collisional virial.
    rms_relative : float
        RMS of s f_LP - f_MD over the matched contacts, in units of the mean MD force.
    n_matched : int
        LP backbone contacts found in the MD record.
    n_lp_contacts : int
        LP backbone contacts.
    md_virial_fraction : float
        Share of the MD collisional virial carried by the matched contacts.
    """

    scale: float
    pressure_ratio: float
    rms_relative: float
    n_matched: int
    n_lp_contacts: int
    md_virial_fraction: float  # share of the MD collisional virial carried by matched contacts

    def as_attrs(self) -> dict:
        """The comparison as dataset attributes.

        Returns
        -------
        dict
            Every field, keyed ``md_force_<field>``.
        """
        return {f"md_force_{k}": v for k, v in self.__dict__.items()}


def _keys(i, j, shift, n: int) -> list[tuple]:
    """Canonical (min, max, shift from min to max) keys; swapping i and j negates the shift."""
    swap = i > j
    a, b = np.where(swap, j, i), np.where(swap, i, j)
    s = np.where(swap[:, None], -shift, shift)
    return [(int(x), int(y), *map(int, z)) for x, y, z in zip(a, b, s)]


def compare_md_forces(net: ContactNetwork, lp_forces: np.ndarray, backbone_contacts: np.ndarray,
                      md) -> ForceComparison:
    """Compare LP forces (on the backbone contacts) with an MD contact-force Dataset ``md`` holding
    md_contact_{i, j, shift, force, virial} (module docstring).

    Parameters
    ----------
    net : ContactNetwork
        The contact network of the LP.
    lp_forces : numpy.ndarray of float, shape (M,)
        LP contact forces.
    backbone_contacts : numpy.ndarray of bool, shape (M,)
        Contacts compared.
    md : xarray.Dataset
        Packing dataset with the MD contact-force variables.

    Returns
    -------
    ForceComparison
        The comparison (NaN entries when no contact matches).
    """
    n = net.n_particles
    md_index = {k: m for m, k in enumerate(_keys(md["md_contact_i"].values, md["md_contact_j"].values,
                                                   md["md_contact_shift"].values, n))}
    lp_keys = _keys(net.i, net.j, net.shift, n)
    rows = np.flatnonzero(backbone_contacts)
    pairs = [(c, md_index[lp_keys[c]]) for c in rows if lp_keys[c] in md_index]
    if not pairs:
        nan = float("nan")
        return ForceComparison(nan, nan, nan, 0, len(rows), nan)
    c, m = map(np.asarray, zip(*pairs))
    # net.normal points from i to j; the MD force is the force on max(i, j) from min(i, j)
    sign = np.where(net.i[c] > net.j[c], -1.0, 1.0)
    f_md = np.einsum("kd,kd->k", md["md_contact_force"].values[m], net.normal[c] * sign[:, None])
    f_lp = lp_forces[c]
    scale = float(f_md @ f_lp / (f_lp @ f_lp))
    md_virial = md["md_contact_virial"].values
    p_lp = scale * float(np.sum(f_lp * net.distance[c]))
    return ForceComparison(
        scale=scale, pressure_ratio=p_lp / float(md_virial.sum()),
        rms_relative=float(np.sqrt(np.mean((scale * f_lp - f_md) ** 2)) / np.mean(f_md)),
        n_matched=len(c), n_lp_contacts=len(rows),
        md_virial_fraction=float(md_virial[m].sum() / md_virial.sum()),
    )
