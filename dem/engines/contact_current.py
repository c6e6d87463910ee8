r"""The electrical submodel of the engine: the current through the contacts as they are, and the Joule heating it
makes in each particle (Zohdi 2014, eqs. 35, 38-44), by either scheme of :mod:`dem.network.current`.

* ``scheme = "kirchhoff"`` -- potentials from one sparse solve per refresh; each contact's electrical conductance is the
  thermal neck law of the scene with :math:`\sigma` in place of :math:`\kappa` (no interface conductance); electrodes
  are walls at a fixed ``potential`` (V) or driving a fixed ``current`` (A into the packing). The heating of a particle
  is the absorption :math:`a` times the Joule heat made in it, :math:`a \sum I^2/G` over its share of its contacts.
* ``scheme = "zohdi"`` -- the paper's area-weighted iteration (eq. 43) over the lens contact areas, warm-started from
  the last refresh; an electrified wall's ``current`` is its :math:`J^\mathrm{ext}`; heating
  :math:`a J_i^2 V_i / \sigma_i` (eq. 35).

The current settles far faster than anything moves (Appendix B: :math:`dP/dt = 0`), so it is refreshed once per accepted
step (Algorithm 1, step 6d), and held while the next step is solved.

A wall at a fixed potential that touches nothing is an open circuit and carries no current; a wall driving a fixed
current with no path to an electrode at a fixed potential cannot, and stops the run. Particles in groups that touch
no electrode carry none ("floating"); with ``[electrical] floating = "error"`` they stop the run, named.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from dem.network.current import (Electrodes, area_weighted_current, kirchhoff, refuse_floating, require_paths,
                                 zohdi_joule)
from dem.laws.conductance import ConductanceSpec, bond_conductances
from dem.geometry.particles import Particles
from dem.engines.staggered.heat import contact_bonds


class ContactCurrent:
    r"""The current of the configuration last refreshed and its heating (module docstring).

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The scene's particles: their electrical conductivity (S/m) and volumes (m^3).
    walls : sequence of dem.geometry.walls.Wall
        The scene's walls.
    electrodes : dem.network.current.Electrodes
        The electrified walls, at a potential (V) or a current (A; Zohdi's scheme: ``J_ext``).
    spec : dem.laws.conductance.ConductanceSpec
        The conductance law, used with :math:`\sigma` for :math:`\kappa` (its interface conductance left out).
    scheme : str
        ``"kirchhoff"`` or ``"zohdi"``.
    absorption : float
        The absorbed fraction a of the Joule heat, in ``[0, 1]`` (eq. 35).
    tolerance : float
        Zohdi's iteration: the largest change per sweep, relative to the largest ``|J_ext|``, at which it stops.
    sweeps : int
        Zohdi's iteration: the most sweeps per refresh.
    linear : str
        Kirchhoff's linear solver (``dem.network.linsolve.BACKENDS``, or ``"auto"``).
    floating : str
        ``"allow"`` or ``"error"`` (particles touching no electrode stop the run).
    """

    name = "electrical"

    def __init__(self, particles: Particles, walls, electrodes: Electrodes, spec: ConductanceSpec, scheme: str,
                 absorption: float, tolerance: float = 1e-8, sweeps: int = 10_000, linear: str = "auto",
                 floating: str = "allow"):
        self.particles, self.walls, self.electrodes = particles, tuple(walls), electrodes
        self.spec = replace(spec, contact_conductance=None)
        self.scheme, self.absorption = scheme, absorption
        self.tolerance, self.sweeps, self.linear, self.floating = tolerance, sweeps, linear, floating
        self.sigma = particles.electrical_conductivity
        self.volume = particles.volume
        n = particles.n
        self.heating = np.zeros(n)         # H_i, W
        self.J = np.zeros(n)               # Zohdi's current per particle; Kirchhoff: the potential (V)
        self.flow = None                   # the last Kirchhoff solution
        self.last_sweeps, self.total_sweeps, self.refreshes, self.open_refreshes = 0, 0, 0, 0
        self.joule_heat, self.electrode_power = 0.0, None
        self.joule_energy, self.electrode_energy = 0.0, 0.0  # J, integrated over the accepted steps
        self.peak_power = 0.0

    def book(self, dt: float) -> None:
        """Add a step of ``dt`` at the current held during it to the energies delivered.

        Parameters
        ----------
        dt : float
            The step (s).
        """
        self.joule_energy += dt * self.joule_heat
        self.electrode_energy += dt * (self.electrode_power or 0.0)
        self.peak_power = max(self.peak_power, self.joule_heat)

    def refresh(self, mech, t: float = 0.0) -> np.ndarray:
        """The current at the state of the mechanics ``mech`` (at time ``t``, for messages): updates
        ``heating``.

        Parameters
        ----------
        mech : dem.engines.staggered.mechanics.StaggeredMechanics
            The mechanics: positions (m), temperatures and walls now.
        t : float
            The time (s), for messages.

        Returns
        -------
        numpy.ndarray
            (N,) the heating of each particle (W).

        Raises
        ------
        ValueError
            A fixed-current electrode has no path, or floating particles with ``floating = "error"``.
        """
        lens = self.scheme == "zohdi"
        now, b = contact_bonds(self.particles, mech, mech.state.x, mech.state.T, self.electrodes.walls,
                               "lens" if lens else self.spec.contact, self.spec.out_of_range)
        n = self.particles.n
        self.refreshes += 1
        if lens:
            res = area_weighted_current(n, b.i, b.j, np.pi * b.a**2, b.wall_particle, b.wall_index,
                                        self.electrodes.current, self.J, self.tolerance, self.sweeps)
            self._check_floating(res.floating, t)
            self.J, self.last_sweeps = res.J, res.sweeps
            self.total_sweeps += res.sweeps
            joule = zohdi_joule(self.J, self.volume, self.sigma, 1.0)
            self.joule_heat, self.electrode_power = float(joule.sum()), None
        else:
            G, G_w, share = bond_conductances(self.spec, now, b, self.sigma, shares=True, box=mech.periodic_box,
                                              walls=[self.walls[k].at(float(mech.w.q[k])) for k in
                                                     self.electrodes.walls])
            self.flow = kirchhoff(n, b.i, b.j, G, share, b.wall_particle, b.wall_index, G_w, self.electrodes,
                                  self.linear, previous=None if self.flow is None else self.flow.solver)
            require_paths(self.flow, self.electrodes, b.wall_index, f" at t = {t:.6g} s")
            self._check_floating(self.flow.floating, t)
            self.J = self.flow.potential
            joule = self.flow.joule_particles
            self.joule_heat, self.electrode_power = self.flow.joule_heat, self.flow.electrode_power
            if not self.flow.closed:
                self.open_refreshes += 1
        self.heating = self.absorption * joule
        return self.heating

    def _check_floating(self, floating: np.ndarray, t: float) -> None:
        if self.floating == "error":
            refuse_floating(floating, f"at t = {t:.6g} s ")

    def electrode_currents(self) -> dict:
        """Current into the packing (A) and potential (V) of each electrode (Kirchhoff), by name."""
        if self.flow is None:
            return {}
        out = {}
        for k, name in enumerate(self.electrodes.names):
            out[f"I_{name}"] = float(self.flow.electrode_current[k])
            out[f"V_{name}"] = float(self.flow.electrode_potential[k])
        return out
