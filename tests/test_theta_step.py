"""One theta step with its linear solve a plug-in (dem.network.theta), and the engines chosen by the registry from the
scene's engine and whether the run is on MPI ranks (dem.engines).

The step is checked against an independent dense solve of ``(C/dt + theta A) T+ = (C/dt - (1-theta) A) T + r``
(Rojek 2022, eqs. 2-4 in time) on the built-in chain (8 particles, the ends held at 10 and 0 C, the inner ones started
at 0 C), for every serial solver: direct to round-off, CG and AMG to their tolerance with the residuals summing to
zero (the balancing shift: the step's heat balance to round-off).
"""

from __future__ import annotations

import numpy as np
import pytest

from dem.engines import RANK_ENGINES, engine_class
from dem.network.heat import build_network
from dem.network.theta import LocalSolves, ThetaStepper
from dem.scene import load_scene


@pytest.fixture(scope="module")
def chain():
    scene = load_scene("chain")
    return build_network(scene.particles, scene.walls, scene.conductance, scene.sources)


def dense_step(net, T, dt, theta):
    """The theta step solved densely with numpy, from the network's matrix and right-hand side."""
    sinks = net.sinks(T)
    A = net.matrix(sinks).toarray()
    C = net.C
    M = np.diag(C / dt) + theta * A
    rhs = C / dt * T - (1.0 - theta) * (A @ T) + net.rhs(sinks)
    return np.linalg.solve(M, rhs), M, rhs


@pytest.mark.parametrize("theta", [1.0, 0.5])
@pytest.mark.parametrize("linear", ["direct", "cg", "amg"])
def test_a_theta_step_is_the_dense_solve_and_keeps_the_heat_balance(chain, theta, linear):
    net = chain
    T = net.particles.temperature[net.free].astype(float)
    dt = 1.0  # s: of the order of the chain's time constants
    T_new, T_theta, _ = ThetaStepper(net, theta, LocalSolves(linear, 1e-12)).step(T, dt)
    expected, M, rhs = dense_step(net, T, dt, theta)
    assert np.ptp(expected) > 1.0  # the step moved the inner particles by whole kelvins
    assert np.max(np.abs(T_new - expected)) <= 1e-9 * np.max(np.abs(expected))
    assert np.array_equal(T_theta, theta * T_new + (1.0 - theta) * T)
    # the step's heat balance: the residuals of M T+ = rhs sum to zero (exact solve, or the balancing shift)
    assert abs(np.sum(rhs - M @ T_new)) <= 1e-12 * np.sum(np.abs(rhs))


def test_the_same_solver_gives_the_same_step_to_the_bit(chain):
    """A stepper's cached solver and a fresh one give the same bits: the step does not depend on its history when
    the start of the solve is given."""
    net = chain
    T = net.particles.temperature[net.free].astype(float)
    stepper = ThetaStepper(net, 0.5, LocalSolves("amg", 1e-10))
    first = stepper.step(T, 0.01, guess=T)[0]
    again = stepper.step(T, 0.01, guess=T)[0]
    fresh = ThetaStepper(net, 0.5, LocalSolves("amg", 1e-10)).step(T, 0.01, guess=T)[0]
    assert np.array_equal(first, again) and np.array_equal(first, fresh)
    assert stepper.factorizations == 1  # one solver per step size


def test_the_registry_chooses_the_engine_from_the_scene_and_the_ranks():
    assert engine_class("static").__name__ == "StaticEngine"
    assert engine_class("static", ranks=True).__name__ == "DistributedStaticEngine"
    assert engine_class("verlet", ranks=True).__name__ == "RankVerletEngine"
    assert set(RANK_ENGINES) == {"static", "verlet"}
    with pytest.raises(ValueError, match=r"^\[solver\] engine = 'staggered': under mpiexec run static packings"):
        engine_class("staggered", ranks=True)
    with pytest.raises(ValueError, match=r"^\[solver\] engine = 'euler': must be one of static, verlet, staggered$"):
        engine_class("euler", ranks=True)


def test_what_the_static_engine_cannot_do_on_ranks_is_refused_before_anything_runs():
    """``cooling`` radiates (a Newton iteration): refused by the class, before MPI or a folder is touched; the
    serial engine refuses nothing up front."""
    cooling = load_scene("cooling")
    engine_class("static").refuse(cooling, resume=False)
    with pytest.raises(ValueError, match=r"^scene 'cooling': radiation \(a Newton iteration\) does not run under MPI"):
        engine_class("static", ranks=True).refuse(cooling, resume=False)
    with pytest.raises(ValueError, match=r"^--resume does not run under MPI"):
        engine_class("static", ranks=True).refuse(load_scene("chain"), resume=True)
