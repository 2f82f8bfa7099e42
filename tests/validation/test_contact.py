"""Contact against physics and REBOUND (``validation.contact``): a hard-sphere gas relaxes to
Maxwell-Boltzmann with the pressure of its equation of state, and a planetesimal disk merges
as REBOUND's "line" search and merge do, keeping mass, momentum and charge."""
import numpy as np
import pytest

from engine import Collisions, Simulation
from validation import contact


@pytest.mark.parametrize("dim", [2, 3])
def test_a_hard_sphere_gas_relaxes_to_maxwell_boltzmann_with_the_equation_of_states_pressure(
        dim):
    n, packing = contact.GAS[dim]
    out = contact.gas_run(dim, n, packing)
    assert out["start_p"] < 1e-6  # the control: one speed for all is far from the law
    assert min(out["p_values"]) > 0.01, out["p_values"]
    assert out["z"] == pytest.approx(out["z_expected"], rel=0.02), (out["z"], out["z_expected"])
    assert out["energy_error"] < 1e-11
    assert out["momentum_error"] < 1e-11 * n


def test_the_speed_test_can_fail_a_distribution_of_the_other_dimension():
    rng = np.random.default_rng(0)
    speeds_3d = np.linalg.norm(rng.normal(size=(2000, 3)), axis=1)  # Maxwell with kT = 1
    assert contact.ks_test(speeds_3d, lambda v: contact.speed_cdf(v, 3, 1.0))[1] > 0.01
    assert contact.ks_test(speeds_3d, lambda v: contact.speed_cdf(v, 2, 1.0))[1] < 1e-6


def test_equations_of_state_at_known_points():
    # Henderson's and Carnahan-Starling's Z at eta = 0.2 and 0.1, worked by hand
    assert contact.compressibility(2, 0.2) == pytest.approx((1 + 0.04 / 8) / 0.64)
    assert contact.compressibility(3, 0.1) == pytest.approx(1.109 / 0.729)


def test_hundreds_of_merges_keep_mass_momentum_and_charge_to_round_off():
    scene = contact.disk(400, 0.03)
    merges, masses, kept = contact.engine_accretion(scene, 1000, 2e-3, "contact")
    assert len(merges) >= 200
    assert len(masses) == 401 - len(merges)
    assert kept["mass"] < 1e-14
    assert kept["momentum"] < 1e-14
    assert kept["charge"] < 1e-14
    # the ledger holds what the merges took: the energy alone changes a million times more
    # than with it (what is left is leapfrog's own error)
    assert kept["energy_with_ledger"] < 1e-8 < kept["energy_without_ledger"] / 1e3


def test_end_of_step_merges_are_rebounds_one_for_one_and_the_statistics_follow():
    out = contact.accretion_run(*contact.ACCRETION["quick"])
    ours, theirs = out["runs"]["end"], out["runs"]["rebound"]
    assert theirs["merges"] >= 50
    # REBOUND's line search and merge, done by the engine: the same bodies absorbed in the
    # same steps, the whole run long on this scene (the disk is chaotic: a longer run parts)
    assert out["identical_end"] == theirs["merges"] == ours["merges"]
    assert ours["merges_by_step"] == theirs["merges_by_step"]
    assert ours["largest_planetesimal"] == pytest.approx(theirs["largest_planetesimal"])
    assert out["end_conservation"]["mass"] < 1e-14
    assert out["end_conservation"]["momentum"] < 1e-14


def test_end_of_step_search_flags_a_pair_that_touched_mid_step_or_overlaps_separating():
    # force-free: a pair that passed through each other within the step (REBOUND's line
    # search finds it from the end velocities), and a pair overlapping at the start while
    # separating, which REBOUND merges too (no approach test); the default leaves it
    for resolve_at, merges in (("end", 2), ("contact", 1)):
        sim = Simulation(dim=2, integrator="leapfrog", dt=1.0)
        sim.add_many(mass=1.0, radius=0.1,
                     pos=[[-1.0, 0.0], [1.0, 0.05], [0.0, 5.0], [0.15, 5.0]],
                     vel=[[2.0, 0.0], [-2.0, 0.0], [-0.01, 0.0], [0.01, 0.0]])
        sim.collisions = Collisions(resolve="merge", resolve_at=resolve_at)
        sim.step(1)
        assert [c.action for c in sim.contacts] == ["merge"] * merges
        assert (sim.contacts[0].i, sim.contacts[0].j) == (0, 1)
        # the merged body is where the pair's centre of mass is, at the end of the step
        np.testing.assert_allclose(sim.pos[0], [0.0, 0.025], atol=1e-15)
        np.testing.assert_allclose(sim.vel[0], [0.0, 0.0], atol=1e-15)
