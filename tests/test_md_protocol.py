"""Two-stage LS protocol (fast growth, then slow growth from a switch pressure) and MD contact
forces (per-pair impulse sums over the final windows).

Physics asserted: the collision virial of the stored pair forces reproduces the window pressure
Z = pV/(NkT) (Donev 2006, sec. 3.2.4.2; sec. 1.1: per-pair exchanged momentum = contact forces),
the time-averaged forces are repulsive central forces along the contact normals, each particle's
net time-averaged force is its momentum change over the window (Newton's third law / momentum
conservation), and the forces of a collectively jammed two-stage packing match the unique
self-stress of its isostatic backbone from the LP verifier.
"""

import subprocess
import sys

import numpy as np
import pytest

from hardpack.distributions import monodisperse
from hardpack.errors import InvalidInputError
from hardpack.initial import random_packing
from hardpack.io import load_dataset, save_packing
from hardpack.md import StopCriteria, compress
from hardpack.md.simulation import Simulation


@pytest.fixture(scope="module")
def mono200():
    return random_packing(200, 3, monodisperse(0.5), 0.3, seed=3)


def _separations(packing, contacts):
    i, j = contacts.md_contact_i.values, contacts.md_contact_j.values
    box = np.diag(packing.lattice)
    return packing.positions[j] + contacts.md_contact_shift.values * box - packing.positions[i]


def test_two_stage_switches_at_the_pressure_and_records_it(mono200):
    res = compress(mono200, 0.05, 1, stop=StopCriteria(max_pressure=1e6), final_growth_rate=0.005,
                   switch_pressure=100.0)
    ts, s = res.timeseries, res.stats
    rates, z = ts.growth_rate.values, ts.Z.values
    k = int(np.argmax(rates == 0.005))  # first slow window
    assert k > 0 and np.all(rates[:k] == 0.05) and np.all(rates[k:] == 0.005)
    assert z[k - 1] >= 100.0 and np.all(z[: k - 1] < 100.0)  # switched right after Z reached 100
    assert s["protocol"] == "lubachevsky_stillinger_two_stage"
    assert s["switch_collisions"] == ts.collisions.values[k - 1]
    assert s["final_stage_collisions"] == s["collisions"] - s["switch_collisions"] > 0
    assert s["final_window_collisions_per_particle"] == 18.0  # 0.03 d / 0.005
    assert s["Z"] >= 1e6 and ts.attrs["final_growth_rate"] == 0.005


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"final_growth_rate": 0.0}, "final_growth_rate"),
        ({"final_growth_rate": float("inf")}, "final_growth_rate"),
        ({"final_growth_rate": 1e-3, "switch_pressure": 0.5}, "switch_pressure"),
        ({"final_growth_rate": 1e-3, "switch_pressure": 1e12}, "never run"),
        ({"contact_forces": True, "contact_windows": 0}, "contact_windows"),
    ],
)
def test_refuses_bad_protocol_options(mono200, kwargs, message):
    with pytest.raises(InvalidInputError, match=message):
        compress(mono200, 0.05, 0, **kwargs)


def test_interrupted_two_stage_run_with_contacts_resumes_bit_identically(tmp_path, mono200):
    """A run stopped by an exception after its checkpoint was written (as a killed process
    would be) and started again ends identical to an uninterrupted run, forces included."""
    kwargs = {"stop": StopCriteria(max_pressure=1e7), "final_growth_rate": 0.01, "switch_pressure": 1e3,
              "contact_forces": True, "contact_windows": 3}
    reference = compress(mono200, 0.05, 2, **kwargs)
    ckpt = tmp_path / "run.npz"
    stop_at = reference.stats["windows"] - 5

    def kill(record):
        if len(seen) >= stop_at:
            raise KeyboardInterrupt
        seen.append(record)

    seen = []
    with pytest.raises(KeyboardInterrupt):
        compress(mono200, 0.05, 2, checkpoint=ckpt, checkpoint_interval=0.0, progress=kill, **kwargs)
    assert ckpt.exists()
    again = compress(mono200, 0.05, 2, checkpoint=ckpt, **kwargs)
    np.testing.assert_array_equal(again.packing.positions, reference.packing.positions)
    for name in reference.contacts.data_vars:
        np.testing.assert_array_equal(again.contacts[name].values, reference.contacts[name].values)
    assert again.stats["switch_collisions"] == reference.stats["switch_collisions"]


def test_contact_force_virial_is_the_window_pressure(mono200):
    """sum_c F_c . r_c / (d V) + N kT / V = Z N kT / V: to round-off with the collision-time
    virials, to ~ the relative gap d/Z with the final contact vectors; forces repulsive and
    central; every particle's net force is its momentum change over the window divided by the
    window's integral of kT dt (one window, no rescaling inside)."""
    res = compress(mono200, 0.02, 1, stop=StopCriteria(max_pressure=1e8), contact_forces=True,
                   contact_windows=1)
    c, p = res.contacts, res.packing
    n, d, volume = p.n_particles, p.dim, p.volume
    z_window = res.timeseries.Z.values[-1]
    pressure = c.md_contact_virial.values.sum() / (d * volume) + n / volume
    assert pressure == pytest.approx(z_window * n / volume, rel=1e-12)
    assert c.attrs["md_contact_Z"] == pytest.approx(z_window, rel=1e-12)
    r = _separations(p, c)
    f = c.md_contact_force.values
    fr = np.einsum("ij,ij->i", f, r)
    assert fr.sum() / (d * volume) + n / volume == pytest.approx(z_window * n / volume, rel=10 * d / z_window)
    dist = np.linalg.norm(r, axis=1)
    assert np.all(fr > 0)  # repulsive
    assert np.all(fr / (np.linalg.norm(f, axis=1) * dist) > 1 - 1e-9)  # central
    sigma = p.radii[c.md_contact_i.values] + p.radii[c.md_contact_j.values]
    assert np.all(np.abs(dist / sigma - 1) < 10 * d / z_window)  # every colliding pair touches
    assert c.attrs["md_contact_total_collisions"] == c.md_contact_collisions.values.sum() > n

    # net force = momentum change / int kT dt, re-run the last window from its start state
    sim = Simulation(p, res.velocities, 0.0, contact_windows=1)
    sim.run_window(2 * n)
    c1 = sim.contacts.result(sim.packing())
    net = np.zeros((n, d))
    np.add.at(net, c1.md_contact_j.values, c1.md_contact_force.values)
    np.add.at(net, c1.md_contact_i.values, -c1.md_contact_force.values)
    kt_time = c1.attrs["md_contact_kT_mean"] * c1.attrs["md_contact_duration"]
    np.testing.assert_allclose(net * kt_time, sim.velocities() - res.velocities, atol=1e-9)


def test_cli_two_stage_with_contact_forces(tmp_path):
    init = tmp_path / "init.nc"
    save_packing(random_packing(100, 2, monodisperse(0.5), 0.5, seed=1), init)
    out = tmp_path / "out.nc"
    cmd = [sys.executable, "-m", "hardpack.md.cli", "compress", "--init", str(init), "--out", str(out),
           "--growth-rate", "0.05", "--seed", "1", "--max-pressure", "1e6", "--final-growth-rate", "0.01",
           "--switch-pressure", "100", "--contact-forces", "--contact-windows", "2"]
    run = subprocess.run(cmd, capture_output=True, text=True, timeout=300, check=False)
    assert run.returncode == 0, run.stderr
    ds = load_dataset(out)
    assert ds.attrs["final_growth_rate"] == 0.01 and ds.attrs["switch_pressure"] == 100.0
    assert ds.attrs["md_contact_windows"] == 2
    assert ds.md_contact_force.dims == ("md_contact", "dim")
    n, d = ds.sizes["particle"], ds.sizes["dim"]
    assert 1 + ds.md_contact_virial.values.sum() / (d * n) == pytest.approx(ds.attrs["md_contact_Z"], rel=1e-12)


@pytest.mark.slow
def test_two_stage_packing_is_isostatic_and_md_forces_are_its_self_stress():
    """2D equimolar binary disks (diameter ratio 1.4), N = 100: Gamma = 0.02 to Z = 1e3, then
    Gamma_f = 1e-4 to Z = 1e12 gives a collectively jammed packing with an isostatic backbone
    (M_b = 2 (N_b - 1) + 1, Donev Eq. 4.8), whose self-stress is unique up to scale. The
    time-averaged MD contact forces of the last 20 windows (~200 collisions per contact) must
    be that self-stress: normalised to mean 1 on the backbone they match the LP forces of the
    verifier to a few percent (rms < 5 %, worst contact < 25 %: the statistical error of ~200
    impulses per contact), and rattlers carry none."""
    from hardpack.distributions import bidisperse
    from hardpack.jamming import verify

    packing = random_packing(100, 2, bidisperse(1.4, 0.5), 0.5, seed=2)
    res = compress(packing, 0.02, 2, stop=StopCriteria(max_pressure=1e12), final_growth_rate=1e-4,
                   switch_pressure=1e3, contact_forces=True, contact_windows=20)
    v = verify(res.packing, md_pressure=res.stats["Z"])
    assert v.collective and v.isostaticity_gap == 0
    net, lp = v.network, v.forces.forces
    c = res.contacts
    md_force = {(int(i), int(j), tuple(s)): np.linalg.norm(f) for i, j, s, f in zip(
        c.md_contact_i.values, c.md_contact_j.values, c.md_contact_shift.values, c.md_contact_force.values)}
    md = np.zeros(net.n_contacts)
    for k in range(net.n_contacts):
        i, j, s = int(net.i[k]), int(net.j[k]), tuple(int(x) for x in net.shift[k])
        if i > j:
            i, j, s = j, i, tuple(-x for x in s)
        md[k] = md_force.get((i, j, s), 0.0)
    backbone = lp > 0
    assert md[~backbone].sum() == 0.0 and len(md_force) == backbone.sum()
    md_n, lp_n = md[backbone] / md[backbone].mean(), lp[backbone] / lp[backbone].mean()
    assert np.sqrt(np.mean((md_n - lp_n) ** 2)) < 0.05
    assert np.max(np.abs(md_n - lp_n)) < 0.25
