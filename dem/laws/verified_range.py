"""Where a run stands against the FE evidence: the summary's account of the necks and of its law's verified range.

**The pair-neck readings** (``newton``, ``first``, ``coble``; Rojek 2022, eqs. 10-34) have no answer once two necks of a
particle meet: a law on them is then outside the range where it is verified, whatever its number.

**The union of spheres.**
Under ``conductance.neck = "union"`` (the union of the spheres, :mod:`fem_neck.geometry.union`) a packing is read at
every density, but the laws were built on pair necks. ``python -m verification densification`` measures them against
the periodic-cell FE of the union (:mod:`fem_neck.lattice`, two-sided bounds) on simple, body- and face-centred cubic
lattices from ``phi`` 0.56 to 0.99 and on random mirror packings of overlapping spheres (radii +-15 %) at ``phi`` 0.6,
0.8 and 0.95. Its relative errors ``k_network / k_FE - 1`` fall into three ranges of the necks, by each particle's
widest neck ``a / r`` (``a`` the lens radius, ``r`` the particle's) and whether two of its necks meet
(:mod:`dem.geometry.necks`):

* **verified**: every neck of the particle at most ``verified_width`` wide and none meeting -- within 1 % of the FE on
  all three lattices;
* **wide**: a neck wider, none meeting -- the interval ``apart``;
* **meeting**: two necks meet -- the interval ``meeting``.

The intervals are the measured extremes, widened by the FE's own tolerance (1e-3 on the lattices, 2e-3 on the random
packings); the study checks every one of its cases against them and fails if one falls outside. A law missing from
:data:`EVIDENCE` was not compared with FE on union necks.

The one-node ``shared-body`` interval for necks apart takes in those cells too: it is +1.13 % and +1.24 % on the FCC
lattice at ``h / r`` 0.12 and 0.14 (``a / r`` 0.34 and 0.37) and +1.15 % to +2.73 % on the BCC lattice at ``h / r``
0.22 to 0.28 (``a / r`` 0.46 to 0.51), where the study's own cases apart stay within 1 %.

**The network's nodes.** With a node per neck (``conductance.nodes = "necks"``, :mod:`dem.network.necks`) the
``shared-body`` particle is solved exactly rather than reduced to one factor per neck: another network, with evidence
of its own, under the name ``"shared-body (neck nodes)"`` (:func:`evidence_name`). Its intervals also take in the
cells of ``python -m verification closing-pores``, which the study does not check but where the neck-node solve was
compared with the same FE: it is within 1 % there up to ``a / r`` 0.456 but +1.1 % and +1.8 % on the BCC lattice
at ``h / r`` 0.25 and 0.28 (``a / r`` 0.48 and 0.51), and +1.3 % on a random packing at ``phi`` 0.85, so its
``verified_width`` stops at the widest study neck below them and its intervals reach them.

**The element.** With the Trefftz element of each cut sphere (``conductance.element = "trefftz"``,
:mod:`dem.network.trefftz_element`, three flux modes per neck) the neck-node network is another again,
``"shared-body (neck nodes, trefftz element)"``. On the 39 union cells of the ``densification`` and ``closing-pores``
studies (SC ``h / r`` 0.05-0.65, BCC 0.05-0.38, FCC 0.05-0.33, seven random mirror packings at ``phi`` 0.6-0.95) it
is within -0.49 % to +0.56 % of the FE's upper bound, necks apart or meeting, where the law's neck-node network is
-4.05 % to +1.81 %: its interval, those extremes widened by the FE's tolerance as the laws' are (-0.69 % to
+0.66 %: +-0.7 %), holds at every neck width and where necks meet. A range whose interval lies within +-1 % is a
verified one (:data:`VERIFIED`): such a run stays in its verified range where necks meet, and its
``law_error_range`` is its own interval.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dem.geometry.necks import PAIR_READINGS, widest_necks


VERIFIED = (-0.01, 0.01)  #: the relative error of k_eff within which a range of the necks is a verified one


@dataclass(frozen=True)
class Evidence:
    """The FE evidence of one law on union necks (module docstring).

    Parameters
    ----------
    verified_width : float
        The widest neck ``a / r`` (dimensionless) up to which the law is within 1 % of the FE where necks do not meet;
        0 where it is not within 1 % even at the narrowest union neck compared.
    apart : tuple of float
        ``(low, high)``: the relative error of ``k_eff`` (dimensionless, -0.1 for -10 %) where necks are wider than
        ``verified_width`` but do not meet.
    meeting : tuple of float
        ``(low, high)``: the relative error of ``k_eff`` (dimensionless) where two necks of a particle meet.
    verified : tuple of float
        ``(low, high)``: the relative error of ``k_eff`` (dimensionless) where every neck is at most
        ``verified_width`` wide and none meets: :data:`VERIFIED`, or the network's own interval where it is narrower.
    """

    verified_width: float
    apart: tuple[float, float]
    meeting: tuple[float, float]
    verified: tuple[float, float] = VERIFIED


TREFFTZ_BAND = (-0.007, 0.007)  # the Trefftz element's network: -0.49 % to +0.56 % on the 39 cells, any neck
#: The FE evidence of each law compared on union necks, by :func:`evidence_name` (module docstring).
EVIDENCE = {
    "shared-body": Evidence(verified_width=0.3123, apart=(-0.010, 0.029), meeting=(-0.037, 0.048)),
    "shared-body (neck nodes)": Evidence(verified_width=0.4360, apart=(-0.010, 0.020), meeting=(-0.043, 0.016)),
    "fit": Evidence(verified_width=0.0, apart=(-0.002, 0.840), meeting=(0.006, 5.47)),
    "argento-bouvard": Evidence(verified_width=0.0, apart=(-0.119, 0.630), meeting=(-0.194, 3.99)),
    "shared-body (neck nodes, trefftz element)": Evidence(verified_width=1.0, apart=TREFFTZ_BAND,
                                                          meeting=TREFFTZ_BAND, verified=TREFFTZ_BAND),
}


def evidence_name(law: str, nodes: str = "particles", element: str = "law") -> str:
    """The name of a law's network in :data:`EVIDENCE` and in the study's columns: the law on one node per particle,
    ``"<law> (neck nodes)"`` with a node per neck as well, ``"<law> (neck nodes, <element> element)"`` with
    elements other than the law's.

    Parameters
    ----------
    law : str
        The conductance law (``dem.laws.conductance.LAWS``).
    nodes : str
        The network's nodes (``dem.laws.conductance.NODES``): ``"particles"`` or ``"necks"``.
    element : str
        The particles' elements with a node per neck (``dem.laws.conductance.ELEMENTS``): ``"law"`` or
        ``"trefftz"``.

    Returns
    -------
    str
        The name.
    """
    if nodes == "particles":
        return law
    return f"{law} (neck nodes)" if element == "law" else f"{law} (neck nodes, {element} element)"


def percent_range(interval: tuple[float, float]) -> str:
    """``"-55.9 % to +2.3 %"`` for ``(-0.559, 0.023)``: a relative-error interval as the warnings print it.

    Parameters
    ----------
    interval : tuple of float
        ``(low, high)``, relative errors (dimensionless).

    Returns
    -------
    str
        The interval in per cent.
    """
    low, high = interval
    return f"{100.0 * low:+.1f} % to {100.0 * high:+.1f} %"


def neck_account(meeting: int, n: int, reading: str, bonds: int, law: str, wide: int = 0,
                 readings: dict | None = None, handed_over: int | None = None, nodes: str = "particles",
                 element: str = "law") -> dict:
    """The summary's account of the necks and of where the law stands (module docstring).

    Entries: the reading every bond used (``neck_readings``: bonds per reading), how many particles carry necks that
    meet (``particles_necks_meeting``), and, for the laws verified against FE (all but ``zohdi``), whether the run
    stayed where its law is verified (``law_in_verified_range``), with one ``warnings`` line per range it left. Under
    the union reading, or in a run that hands particles whose necks meet over to it (:mod:`dem.engines.handover`,
    ``particles_handed_over``), a law with FE evidence there also reports ``law_error_range``: the relative error of
    ``k_eff`` (``[low, high]``, dimensionless) the evidence allows over the ranges the run reached; under the union
    reading also ``particles_necks_wide``. With a node per neck (``nodes``) the evidence and the warnings are those of
    the neck-node network with its ``element`` (:func:`evidence_name`). A range the run reached whose interval lies
    within :data:`VERIFIED` keeps it in the verified range, without a warning.

    Parameters
    ----------
    meeting : int
        Particles that carry necks that meet.
    n : int
        Particles in the run.
    reading : str
        The neck reading of the scene (``dem.geometry.bonds.CONTACT_MODELS``).
    bonds : int
        Pair and wall bonds.
    law : str
        The conductance law (``dem.laws.conductance.LAWS``).
    wide : int
        Particles whose necks do not meet but one of which is wider than the law's ``verified_width``
        (:func:`wide_necks`); union reading only.
    readings : dict or None
        Bonds per reading where they differ (a hand-over); None: all ``bonds`` read ``reading``.
    handed_over : int or None
        Particles handed over to the union; None: the run hands none over.
    nodes : str
        The network's nodes (``conductance.nodes``): ``"particles"`` or ``"necks"``.
    element : str
        The particles' elements with a node per neck (``conductance.element``): ``"law"`` or ``"trefftz"``.

    Returns
    -------
    dict
        The summary's entries.
    """
    meeting, wide = int(meeting), int(wide)
    out = {"neck_readings": {reading: int(bonds)} if readings is None else {k: int(v) for k, v in readings.items()},
           "particles_necks_meeting": meeting}
    if handed_over is not None:
        out["particles_handed_over"] = int(handed_over)
    if reading not in PAIR_READINGS and reading != "union":
        return out
    if reading in PAIR_READINGS:
        out["law_in_verified_range"] = meeting == 0
        if not meeting:
            return out
        if handed_over is None:
            out["warnings"] = [f"{_share(meeting, n)} carry necks that meet: the pair-neck reading {reading!r} has no "
                               f"answer there, so law {law!r} is outside the range where it is verified; "
                               f"conductance.neck = \"union\" reads the packing as the union of its spheres, defined at "
                               f"every density"]
            return out
        wide = 0  # the pair necks are verified while apart; the union reads only the handed-over particles
    law = evidence_name(law, nodes, element)
    evidence = EVIDENCE.get(law)
    if evidence is None:
        out["law_in_verified_range"] = False
        out["warnings"] = [f"law {law!r} was not compared with FE on union necks (python -m verification "
                           f"densification compares {', '.join(EVIDENCE)}): no error bound"]
        return out
    if reading == "union":
        out["particles_necks_wide"] = wide
    reached = [interval for count, interval in ((wide, evidence.apart), (meeting, evidence.meeting)) if count]
    out["law_in_verified_range"] = all(_within(interval, VERIFIED) for interval in reached)
    out["law_error_range"] = ([min(r[0] for r in reached), max(r[1] for r in reached)] if reached
                              else list(evidence.verified))
    wide = wide if not _within(evidence.apart, VERIFIED) else 0  # (the warnings: ranges that are not verified)
    meeting = meeting if not _within(evidence.meeting, VERIFIED) else 0
    warnings = []
    if wide:
        warnings.append(f"{_share(wide, n)} carry a neck wider than a/r = {evidence.verified_width:g} (none meeting): "
                        f"FE of the union puts law {law!r} at {percent_range(evidence.apart)} of k_eff there")
    if meeting:
        read = "carry necks that meet" if reading == "union" else "carry necks that meet, read as the union"
        warnings.append(f"{_share(meeting, n)} {read}: FE of the union puts law {law!r} at "
                        f"{percent_range(evidence.meeting)} of k_eff there")
    if warnings:
        out["warnings"] = warnings
    return out


def wide_necks(radius: np.ndarray, bonds, meeting: np.ndarray, law: str, nodes: str = "particles",
               element: str = "law") -> np.ndarray:
    """Per particle, whether its necks do not meet but one is wider than the ``verified_width`` of the law's network
    on union necks (all False under another reading or for a network without FE evidence there).

    Parameters
    ----------
    radius : numpy.ndarray
        Particle radii, m.
    bonds : dem.geometry.bonds.Bonds
        The pair and wall bonds with their neck radii (m) and reading.
    meeting : numpy.ndarray
        Per particle, whether two of its necks meet (bool, :func:`dem.geometry.necks.meeting_in`).
    law : str
        The conductance law.
    nodes : str
        The network's nodes (``conductance.nodes``): ``"particles"`` or ``"necks"``.
    element : str
        The particles' elements with a node per neck (``conductance.element``): ``"law"`` or ``"trefftz"``.

    Returns
    -------
    numpy.ndarray
        Bool per particle.
    """
    evidence = EVIDENCE.get(evidence_name(law, nodes, element))
    if bonds.contact != "union" or evidence is None:
        return np.zeros(len(radius), dtype=bool)
    return ~np.asarray(meeting, dtype=bool) & (widest_necks(radius, bonds) > evidence.verified_width)


def _within(interval: tuple[float, float], band: tuple[float, float]) -> bool:
    return band[0] <= interval[0] and interval[1] <= band[1]


def _share(count: int, n: int) -> str:
    return f"{count} of {n} particles ({100.0 * count / n:.1f} %)"
