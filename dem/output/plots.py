"""The plots a run folder gets at its end (matplotlib, imported only here, only when a run writes plots).

* :func:`motion_plots` -- a run with moving particles: ``timeseries.png`` (solid fraction, coordination number,
  kinetic energy, stiffness factor k1(T, t)/k1, temperatures, wall stresses and, with heated walls, the effective
  conductivity, each against time) and ``profiles.png`` (solid fraction and neck radius against the distance from
  the hot wall, one curve per snapshot time); with a Joule-heated run (a ``joule_heat`` column),
  ``fraction_temperature.png``: the volume fraction and the mean temperature against time on two axes, the times
  when current flows shaded (Zohdi 2014, Fig. 9).
"""

from __future__ import annotations

import csv
import pathlib

import numpy as np

from dem.output.atomic import write_aside


def _save(fig, path: pathlib.Path) -> None:
    """``fig`` as a PNG at ``path``, written aside and renamed (:mod:`dem.output.atomic`)."""
    write_aside(path, lambda fh: fig.savefig(fh, format="png", dpi=120), "wb")


def _read_csv(path: pathlib.Path) -> dict:
    with path.open() as fh:
        rows = list(csv.DictReader(fh))
    if not rows:
        return {}
    return {k: [float(r[k]) if r[k] not in ("", None) else float("nan") for r in rows] for k in rows[0]}


TEMPERATURE_UNITS = {"C": "°C", "K": "K"}  # [scene] temperature_unit: the symbol on the plots' axes


def temperature_label(unit: str, what: str = "temperature") -> str:
    """An axis label with the scene's temperature unit (``[scene] temperature_unit``: "C" or "K").

    Parameters
    ----------
    unit : str
        ``"C"`` or ``"K"``.
    what : str
        The quantity named before the unit.

    Returns
    -------
    str
        ``"<what> (<symbol>)"``.
    """
    return f"{what} ({TEMPERATURE_UNITS[unit]})"


def motion_plots(out_dir, temperature_unit: str, wall_unit: str) -> list[str]:
    """Write the plots of a moving-particle run folder; returns the file names written. ``temperature_unit``: the
    scene's ("C" or "K"); ``wall_unit``: that of the ``wall_*`` columns ("Pa", "N/m" or "N", one for all walls).

    Parameters
    ----------
    out_dir : str or pathlib.Path
        The run folder (its ``timeseries.csv`` is read).
    temperature_unit : str
        ``"C"`` or ``"K"``.
    wall_unit : str
        The unit of the wall loads: ``"Pa"``, ``"N/m"`` or ``"N"``.

    Returns
    -------
    list of str
        The names of the files written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = pathlib.Path(out_dir)
    data = _read_csv(out / "timeseries.csv") if (out / "timeseries.csv").exists() else {}
    written = []
    if data:
        t = data["t"]
        panels = [("volume_fraction", "solid fraction"), ("coordination", "coordination number"),
                  ("kinetic_energy", "kinetic energy (J)"), ("k1_factor", "k1(T, t) / k1 (mean)"),
                  ("T_mean", temperature_label(temperature_unit)), ("effective_conductivity", "k_eff (W/(m K))")]
        panels = [(k, label) for k, label in panels if k in data and any(v == v for v in data[k])]
        walls = [k for k in data if k.startswith("wall_")]
        if walls:
            panels.append(("walls", f"wall load ({wall_unit})"))
        fig, axes = plt.subplots(len(panels), 1, figsize=(7, 2.0 * len(panels)), sharex=True, squeeze=False)
        for ax, (key, label) in zip(axes[:, 0], panels):
            if key == "walls":
                for w in walls:
                    ax.plot(t, data[w], label=w[5:])
                ax.legend(fontsize=7)
            elif key == "T_mean":
                ax.plot(t, data["T_mean"], label="mean")
                ax.fill_between(t, data["T_min"], data["T_max"], alpha=0.3, label="min-max")
                ax.legend(fontsize=7)
            else:
                ax.plot(t, data[key])
            if key == "kinetic_energy":
                ax.set_yscale("log")
            ax.set_ylabel(label, fontsize=8)
        axes[-1, 0].set_xlabel("t (s)")
        fig.tight_layout()
        _save(fig, out / "timeseries.png")
        plt.close(fig)
        written.append("timeseries.png")
    if data and "joule_heat" in data and "volume_fraction" in data and "T_mean" in data:
        written.append(_fraction_temperature(plt, out, data, temperature_unit))
    if (out / "profiles.csv").exists():
        prof = _read_csv(out / "profiles.csv")
        if prof:
            fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
            times = sorted(set(prof["t"]))
            for time in times:
                rows = [k for k, tt in enumerate(prof["t"]) if tt == time]
                d = [prof["distance"][k] * 1e3 for k in rows]
                a1.plot(d, [prof["solid_fraction"][k] for k in rows], "o-", ms=3, label=f"t = {time:.3g} s")
                a2.plot(d, [prof["neck_over_radius"][k] for k in rows], "o-", ms=3, label=f"t = {time:.3g} s")
            a1.set_xlabel("distance from the hot wall (mm)")
            a2.set_xlabel("distance from the hot wall (mm)")
            a1.set_ylabel("solid fraction")
            a2.set_ylabel("neck radius a / r (mean over contacts)")
            a2.legend(fontsize=7)
            fig.tight_layout()
            _save(fig, out / "profiles.png")
            plt.close(fig)
            written.append("profiles.png")
    return written


def thermal_plots(out_dir, scene, T) -> list[str]:
    """Write the plots of a thermal (static packing) run folder; returns the file names written.

    * ``temperature.png`` -- mean, min and max temperature against time (transient);
    * ``heat_flow.png`` -- heat flow into the particles through fixed particles, walls, convection, radiation and
      internal sources against time (transient; the boundaries the scene has);
    * ``profile.png`` -- the temperature of every particle against its place along the heat-flow axis (the
      specimen's, :mod:`dem.scene.specimen`) with the mean of slabs, and the effective conductivity when the run
      reports one (scenes with a hot and a cold end).

    Parameters
    ----------
    out_dir : str or pathlib.Path
        The run folder (its ``timeseries.csv`` is read).
    scene : dem.scene.parse.Scene
        The scene (particles, specimen, temperature unit).
    T : numpy.ndarray
        (N,) the particles' final temperatures (K or degC).

    Returns
    -------
    list of str
        The names of the files written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = pathlib.Path(out_dir)
    written = []
    data = _read_csv(out / "timeseries.csv") if (out / "timeseries.csv").exists() else {}
    if scene.solver.mode == "transient" and data:
        fig, ax = plt.subplots(figsize=(7, 4))
        ax.plot(data["t"], data["T_mean"], label="mean")
        ax.fill_between(data["t"], data["T_min"], data["T_max"], alpha=0.3, label="min-max")
        ax.set_xlabel("t (s)")
        ax.set_ylabel(temperature_label(scene.temperature_unit))
        ax.legend()
        fig.tight_layout()
        _save(fig, out / "temperature.png")
        plt.close(fig)
        written.append("temperature.png")
        flows = [k for k in data if k.startswith("Q_") and any(abs(v) > 0 for v in data[k])]
        if flows:
            fig, ax = plt.subplots(figsize=(7, 4))
            for k in flows:
                ax.plot(data["t"], data[k], label=k[2:])
            ax.set_xlabel("t (s)")
            ax.set_ylabel("heat flow into the particles (W)")
            ax.legend()
            fig.tight_layout()
            _save(fig, out / "heat_flow.png")
            plt.close(fig)
            written.append("heat_flow.png")
    if scene.specimen is not None:
        axis = scene.specimen.axis
        z = scene.particles.position[:, axis]
        fig, ax = plt.subplots(figsize=(7, 4))
        ax.plot(z * 1e3, T, ".", ms=2, alpha=0.4, label="particles")
        edges = np.linspace(z.min(), z.max(), 21)
        slab = np.clip(np.searchsorted(edges, z) - 1, 0, 19)
        count = np.bincount(slab, minlength=20)
        with np.errstate(invalid="ignore"):
            mean = np.bincount(slab, T, 20) / count
        ax.plot(0.5 * (edges[1:] + edges[:-1]) * 1e3, mean, "o-", label="slab mean")
        ax.set_xlabel(f"{'xyz'[axis]} (mm), along the heat flow")
        ax.set_ylabel(temperature_label(scene.temperature_unit))
        summary = out / "summary.json"
        title = ""
        if summary.exists():
            import json

            k_eff = json.loads(summary.read_text()).get("effective_conductivity")
            title = f"k_eff = {k_eff:.6g} W/(m K)" if k_eff is not None else ""
        ax.set_title(title)
        ax.legend()
        fig.tight_layout()
        _save(fig, out / "profile.png")
        plt.close(fig)
        written.append("profile.png")
    return written


def _fraction_temperature(plt, out: pathlib.Path, data: dict, temperature_unit: str) -> str:
    """Volume fraction and mean temperature against time, the times with current shaded (Zohdi 2014, Fig. 9)."""
    t = data["t"]
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(t, data["volume_fraction"], color="tab:blue")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("volume fraction", color="tab:blue")
    other = ax.twinx()
    other.plot(t, data["T_mean"], color="tab:red")
    other.set_ylabel(temperature_label(temperature_unit, "mean temperature"), color="tab:red")
    peak = max((v for v in data["joule_heat"] if v == v), default=0.0)
    on = [v == v and v > 1e-9 * peak for v in data["joule_heat"]]  # not the round-off of an open circuit
    ax.fill_between(t, 0, 1, where=on, transform=ax.get_xaxis_transform(), color="gold", alpha=0.25,
                    label="current flowing")
    ax.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    _save(fig, out / "fraction_temperature.png")
    plt.close(fig)
    return "fraction_temperature.png"
