"""Regression tests for the CLI stress defects found by fuzzing ``python -m fem_neck | dem | verification``.

Every case calls the CLI ``main`` in process and requires what the project asks of bad input: exit code 2
with one line on stderr naming the parameter (and its range), or a correct answer -- never a traceback, a NaN or
a hang. The defect each test guards is in its docstring or comment.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from dem.cli import main as dem_main
from fem_neck import neck_radius
from fem_neck.cli import main as fem_main
from verification.cli import main as verification_main

MATERIAL = "[material]\nconductivity = {k}\ndensity = 8960.0\nspecific_heat = 385.0\n"
PAIR = ("[particles]\nposition = {pos}\nradius = {r}\ntemperature = {T}\n")
TRANSIENT = '[solver]\nmode = "transient"\nintegrator = "{integ}"\ndt = {dt}\nt_end = {t_end}\n'
STEADY = '[solver]\nmode = "steady"\n'


def scene(k="394.0", pos="[[0.0, 0.0, 0.0], [0.0, 0.0, 3.94e-3]]", r="[1.0e-3, 3.0e-3]", T="[100.0, 0.0]",
          extra="", solver=None, integ="implicit", dt="1.0e-3", t_end="0.01") -> str:
    return (MATERIAL.format(k=k) + PAIR.format(pos=pos, r=r, T=T) + extra
            + (solver if solver is not None else TRANSIENT.format(integ=integ, dt=dt, t_end=t_end)))


def run_cli(main, argv, capsys):
    """``(exit code, stdout, stderr lines)``; an exception escaping ``main`` fails the test (a traceback)."""
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, [line for line in err.splitlines() if line.strip()]


def assert_refused(main, argv, capsys, *needles):
    code, out, err = run_cli(main, argv, capsys)
    assert code == 2, (code, out[:300], err)
    assert len(err) == 1, err
    for needle in needles:
        assert needle.lower() in err[0].lower(), (needle, err[0])
    assert out == ""
    return err[0]


def run_scene(tmp_path, text, capsys, name="s"):
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return run_cli(dem_main, ["run", str(path), "--json"], capsys)


def refuse_scene(tmp_path, text, capsys, *needles):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    return assert_refused(dem_main, ["run", str(path), "--json"], capsys, *needles)


def finite_json(out: str) -> dict:
    assert "NaN" not in out and "Infinity" not in out, out[:300]
    return json.loads(out)


# ------------------------------------------------------------------------------------------------- dem: scenes
@pytest.mark.parametrize("table, key", [
    ('[conductance]\nslope = "x"\n', "slope"),
    ('[conductance]\ncontact_conductance = "x"\n', "contact_conductance"),
    ('[convection]\nh = "x"\nT_inf = 20.0\n', "h"),
    ('[convection]\nh = 10.0\nT_inf = "x"\n', "T_inf"),
])
def test_text_for_a_number_is_named(tmp_path, capsys, table, key):
    """Was a TypeError traceback (``np.isfinite`` of a string)."""
    refuse_scene(tmp_path, scene(extra=table), capsys, key, "finite number")


@pytest.mark.parametrize("kwargs, needles", [
    ({"k": "1e300"}, ("conductivity", "1e+10")),                                      # was: singular factor
    ({"T": "[1e308, -1e308]"}, ("temperature[0]", "1e+12")),                           # was: non-finite T
    ({"pos": "[[0.0, 0.0, 0.0], [0.0, 0.0, 1.9e7]]", "r": "[1e7, 1e7]"}, ("radius[0]", "1e+06")),  # 1e100: NaN
    ({"pos": "[[0.0, 0.0, 0.0], [0.0, 0.0, 1e300]]"}, ("position[1][2]", "1e+12")),   # was: cKDTree overflow
    ({"extra": "[[walls]]\npoint = [0.0, 0.0, 1e13]\nnormal = [0.0, 0.0, 1.0]\ntemperature = 1.0\n"},
     ("point[2]", "1e+12")),
    ({"extra": "[[walls]]\npoint = ['x', 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\ntemperature = 1.0\n"},
     ("point", "3-vector")),                                                           # was: unnamed float error
])
def test_magnitudes_outside_the_documented_range(tmp_path, capsys, kwargs, needles):
    refuse_scene(tmp_path, scene(**kwargs), capsys, *needles)


@pytest.mark.parametrize("T, T_inf, needle", [
    ("[300.0, 300.0]", "1e80", "T_inf"),     # was: exit 0 with NaN temperatures
    ("[1e6, 300.0]", "300.0", "temperature[0]"),
])
def test_radiation_temperatures_beyond_the_model(tmp_path, capsys, T, T_inf, needle):
    rad = f"[radiation]\nemissivity = 1.0\nT_inf = {T_inf}\nunit = \"K\"\n"
    refuse_scene(tmp_path, scene(T=T, extra=rad, solver=STEADY), capsys, needle, "10000")


def test_radiation_without_a_temperature_unit_is_refused(tmp_path, capsys):
    """20 C and 20 K radiate very differently: a scene with radiation must say which it means."""
    rad = "[radiation]\nemissivity = 1.0\nT_inf = 20.0\n"
    refuse_scene(tmp_path, scene(T="[300.0, 300.0]", extra=rad, solver=STEADY), capsys, "radiation", "unit")


def test_radiation_at_the_range_limit_balances(tmp_path, capsys):
    """A particle fixed at 1e4 K radiating, its neighbour between: steady answer with a closed energy balance."""
    rad = "[radiation]\nemissivity = 1.0\nT_inf = 300.0\nunit = \"K\"\n"
    code, out, _ = run_scene(tmp_path, scene(T="[1e4, 300.0]", extra=rad + "", solver=STEADY)
                             .replace("temperature = [1e4, 300.0]\n", "temperature = [1e4, 300.0]\nfixed = [true, false]\n"),
                             capsys)
    s = finite_json(out)
    assert code == 0 and 300.0 < s["T"][1] < 1e4 and s["energy_error"] < 1e-10


def test_lens_clip_coincident_particles_refused(tmp_path, capsys):
    """Was exit 0 with K = 0: two coincident spheres silently uncoupled."""
    text = scene(pos="[[0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]", r="[1e-3, 1e-3]",
                 extra='[conductance]\nlaw = "zohdi"\nout_of_range = "clip"\n')
    refuse_scene(tmp_path, text, capsys, "coincide", "out_of_range")


def test_lens_clip_contained_sphere_equalises_to_the_energy_mean(tmp_path, capsys):
    """Was 'temperatures became non-finite' (a = 0 over a pipe of length 0 gave NaN). A small sphere inside a big one
    is clipped to the big one's equator contact: both end at the capacity-weighted mean (energy conservation)."""
    text = scene(pos="[[0.0, 0.0, 0.0], [0.0, 0.0, 1e-4]]", r="[1e-3, 1e-5]", T="[100.0, 0.0]",
                 extra='[conductance]\nlaw = "zohdi"\nout_of_range = "clip"\n', dt='"auto"')
    code, out, _ = run_scene(tmp_path, text, capsys)
    s = finite_json(out)
    mean = 100.0 * 1e-3**3 / (1e-3**3 + 1e-5**3)
    assert code == 0 and s["bonds_clipped"] == 1
    assert s["T"] == pytest.approx([mean, mean], rel=1e-9)


def test_lens_clip_centre_behind_a_wall_refused(tmp_path, capsys):
    """Was exit 0 with NaN temperatures (infinite wall conductance). A centre behind the wall is refused with the
    scene; one on the wall's plane by its infinite conductance."""
    for z, needles in (("0.5e-3", ("particle 0", "behind wall 'wall0'")), ("0.0", ("wall bond of particle 0", "finite"))):
        wall = f"[[walls]]\npoint = [0.0, 0.0, {z}]\nnormal = [0.0, 0.0, 1.0]\ntemperature = 1.0\n"
        text = scene(extra='[conductance]\nlaw = "zohdi"\nout_of_range = "clip"\n' + wall, solver=STEADY)
        refuse_scene(tmp_path, text, capsys, *needles)


def test_numerically_singular_step_is_explained(tmp_path, capsys):
    """Was a SuperLU 'Factor is exactly singular' traceback: capacities 1e-56 J/K against dt = 1e6 s."""
    text = (MATERIAL.format(k="1e10").replace("8960.0", "1e-10").replace("385.0", "1e-10")
            + PAIR.format(pos="[[0.0, 0.0, 0.0], [0.0, 0.0, 1.9e-12]]", r="[1e-12, 1e-12]", T="[100.0, 0.0]")
            + TRANSIENT.format(integ="implicit", dt="1e6", t_end="1e6"))
    refuse_scene(tmp_path, text, capsys, "numerically singular", "solver.dt")


@pytest.mark.parametrize("body, needle", [
    ('kind = "chain"\nn = 3\nradius = 1e-3\noverlap = 5.0\n', "overlap[0]"),           # was: 3 particles, no bonds
    ('kind = "lattice"\nshape = [9223372036854775807, 2, 2]\nradius = 1e-3\noverlap = 0.1\n', "shape"),  # overflow
    ('kind = "lattice"\nshape = [2, 2, 2]\nradius = 1e-3\noverlap = 0.7\n', "overlap"),
    ('kind = "random"\nn = 100\nradius = 1e-3\noverlap = 0.1\nseed = -1\n', "seed"),
    ('kind = "random"\nn = 100\nradius = 1e-3\noverlap = 0.1\nradius_spread = "x"\n', "radius_spread"),
    ('kind = "random"\nn = 1000000000000\nradius = 1e-3\noverlap = 0.1\n', "n"),
])
def test_generator_parameters_named(tmp_path, capsys, body, needle):
    refuse_scene(tmp_path, MATERIAL.format(k="394.0") + "[generator]\n" + body + STEADY, capsys, needle)


def test_tiny_rtol_refused_up_front(tmp_path, capsys):
    """Was a 76 s run ending in max_steps (rtol = 1e-300 shrinks dt = "auto" to round-off)."""
    refuse_scene(tmp_path, scene(dt='"auto"', extra="") + "rtol = 1e-300\n", capsys, "rtol", "1e-09")


def test_step_count_refused_before_running(tmp_path, capsys):
    """1e6 fixed steps of a pair took ~100 s; the default max_steps (1e5) refuses them up front."""
    refuse_scene(tmp_path, scene(dt="1e-5", t_end="10.0"), capsys, "max_steps", "1e+06")


def test_particle_steps_refused_with_an_estimate(tmp_path, capsys):
    """10^6 particles x 1000 implicit steps (~100-600 s) was attempted; now refused before the bond search."""
    text = (MATERIAL.format(k="394.0") + '[generator]\nkind = "lattice"\nshape = [100, 100, 100]\nradius = 1e-3\n'
            'overlap = 0.1\n' + TRANSIENT.format(integ="implicit", dt="1e-3", t_end="1.0"))
    refuse_scene(tmp_path, text, capsys, "particle-steps", "max_steps")


def test_snapshot_flood_refused_and_collection_complete(tmp_path, capsys):
    """vtu_every = 1 over 1e4 steps wrote 2e4 files and rewrote the PVD each time (~100 s, quadratic); now refused.
    A short run still lists every snapshot in its PVD (the collection is rewritten at powers of two and at the end)."""
    out = str(tmp_path / "out")
    text = scene(dt="1e-4", t_end="1.0") + "[output]\nvtu_every = 1\n"
    (tmp_path / "flood.toml").write_text(text)
    assert_refused(dem_main, ["run", str(tmp_path / "flood.toml"), "--out", out], capsys, "vtu_every", ">= 10")
    (tmp_path / "short.toml").write_text(scene(dt="1e-3", t_end="0.007") + "[output]\nvtu_every = 1\n")
    code, _, _ = run_cli(dem_main, ["run", str(tmp_path / "short.toml"), "--out", out, "--json"], capsys)
    files = sorted(p.name for p in (tmp_path / "out").glob("particles_*.vtu"))
    listed = (tmp_path / "out" / "particles.pvd").read_text().count("<DataSet")
    assert code == 0 and len(files) == 8 and listed == 8


def test_explicit_step_around_the_stable_limit(tmp_path, capsys):
    """0.49x the limit runs and stays inside the initial range (maximum principle); 0.99x is stable but oscillates
    ~90 C outside it (a wrong answer: refused, naming dt); 1.01x is refused as unstable."""
    from dem.engines.static import StaticEngine
    from dem.scene import parse_scene
    from dem.network.heat import stable_limit

    import tomllib

    limit = stable_limit(StaticEngine(parse_scene(tomllib.loads(scene()))).network)
    code, out, _ = run_scene(tmp_path, scene(integ="explicit", dt=repr(0.49 * limit), t_end=repr(50 * limit)),
                             capsys)
    s = finite_json(out)
    assert code == 0 and 0.0 <= min(s["T"]) and max(s["T"]) <= 100.0 and s["max_principle_violation"] == 0.0
    refuse_scene(tmp_path, scene(integ="explicit", dt=repr(0.99 * limit), t_end=repr(50 * limit)), capsys,
                 "solver.dt", "max_principle_violation")
    refuse_scene(tmp_path, scene(integ="explicit", dt=repr(1.01 * limit), t_end=repr(50 * limit)), capsys,
                 "solver.dt", "stability limit")


# ---------------------------------------------------------------------------------------------- fem_neck
def test_radii_1e600_apart_are_a_sphere_on_a_plane(capsys):
    """Radii 1e600 apart (used to overflow: warnings and a 'valid range 0 < h <= nan' refusal): the larger sphere
    is a plane, and the neck is the same as at any ratio beyond ~1e16, with no warning."""
    code, out, err = run_cli(fem_main, ["neck", "--ri", "1e-300", "--rj", "1e300", "--h", "1e-301", "--json"],
                             capsys)
    far = neck_radius(1.0, 1e20, 0.1)
    assert code == 0 and err == [] and finite_json(out)["a"] == pytest.approx(far * 1e-300, rel=1e-12)


def test_warnings_on_success_are_one_line_each(capsys):
    code, out, err = run_cli(fem_main, ["neck", "--ri", "1e300", "--rj", "1e-3", "--h", "1e-4", "--json"], capsys)
    s = finite_json(out)
    assert code == 0 and all(line.startswith("python -m fem_neck neck: warning: ") for line in err), err
    assert s["a"] == pytest.approx(math.sqrt(2 * 2e-3 * 1e-4), rel=0.05)  # Coble-like small neck of a sphere on a plane


@pytest.mark.parametrize("argv, needle", [
    (["fit", "--points", "1000000000000", "--json"], "points"),               # was: MemoryError traceback
    (["chain", "--radii", ",".join(["1e-3"] * 200), "--overlaps", ",".join(["1e-4"] * 199), "--kappa", "394"],
     "radii"),                                                                  # was: > 120 s
    (["pair", "--ri", "1e-3", "--rj", "1e300", "--h", "6e-5", "--kappa", "394"], "r_j / r_i"),  # OverflowError
    (["pair", "--ri", "1e-3", "--rj", "1e6", "--h", "6e-5", "--kappa", "394"], "r_j / r_i"),   # unconverged K
    (["unequal", "--ratios", ",".join(["2"] * 100), "--necks", "0.1,0.2,0.3"], "ratios x necks"),
])
def test_huge_fe_requests_refused_up_front(capsys, argv, needle):
    assert_refused(fem_main, argv, capsys, needle)


def _cluster(tmp_path, data) -> str:
    path = tmp_path / "cluster.json"
    path.write_text(json.dumps(data))
    return str(path)


GOOD = {"centres": [[0, 0, 0], [0, 0, 1.92e-3]], "radii": [1e-3, 1e-3], "bonds": [[0, 1]],
        "terminals": [{"particle": 0, "T": 1.0}, {"particle": 1, "T": 0.0}]}


@pytest.mark.parametrize("change, needle", [
    ({"bonds": [[0.5, 1]]}, "bonds[0][0]"),             # was: silently truncated to particle 0
    ({"radii": ["a", 1e-3]}, "radii[0]"),               # was: unnamed 'could not convert string to float'
    ({"centres": [[0, 0], [0, 1.92e-3]]}, "centres[0]"),  # was: 'cannot reshape array'
    ({"terminals": [{"particle": 0, "T": 1.0, "hot": 1}, {"particle": 1, "T": 0.0}]}, "terminals[0].hot"),
    ({"extra": 1}, "extra"),
])
def test_cluster_file_entries_named(tmp_path, capsys, change, needle):
    assert_refused(fem_main, ["cluster", _cluster(tmp_path, {**GOOD, **change}), "--levels", "1"], capsys, needle)


@pytest.mark.parametrize("options, needle", [
    (["--size-far", "0"], "size_far"),            # was: ZeroDivisionError traceback
    (["--size-far", "nan"], "size_far"),          # was: 'cannot convert float NaN to integer'
    (["--size-neck", "1e-300"], "size_neck"),     # was: a hang
])
def test_cluster_mesh_sizes_bounded(tmp_path, capsys, options, needle):
    assert_refused(fem_main, ["cluster", _cluster(tmp_path, GOOD), *options], capsys, needle, "valid range")


def test_cluster_run_time_estimate_refuses_huge_meshes(tmp_path, capsys):
    n = 12
    data = {"centres": [[0, 0, 1.9e-3 * k] for k in range(n)], "radii": [1e-3] * n,
            "bonds": [[k, k + 1] for k in range(n - 1)], "terminals": [{"particle": 0, "T": 1.0},
                                                                     {"particle": n - 1, "T": 0.0}]}
    assert_refused(fem_main, ["cluster", _cluster(tmp_path, data), "--size-far", "0.05", "--size-neck", "0.02"],
                   capsys, "estimated", "budget")


@pytest.mark.slow
def test_cluster_extreme_kappa_scales_exactly(tmp_path, capsys):
    """kappa = 1e-300 used to give wrong temperatures (0.53/0.47 instead of 0.898/0.102): the FE solve underflowed.
    K is linear in kappa and the temperatures independent of it."""
    path = _cluster(tmp_path, GOOD)
    runs = []
    for kappa in ("1e-300", "1e300"):
        code, out, _ = run_cli(fem_main, ["cluster", path, "--kappa", kappa, "--levels", "1", "--json"], capsys)
        assert code == 0
        runs.append(finite_json(out))
    assert runs[0]["K"] * 1e300 == pytest.approx(runs[1]["K"] / 1e300, rel=1e-12)
    assert np.allclose(runs[0]["particle_T"], runs[1]["particle_T"], rtol=1e-12)
    assert runs[0]["particle_T"][0] == pytest.approx(1.0 - runs[0]["particle_T"][1], abs=1e-3)  # antisymmetry
    assert runs[0]["particle_T"][0] > 0.85  # the hot particle (0.898 at kappa = 394)


# ------------------------------------------------------------------------------------------ verification
@pytest.mark.parametrize("out", ["/dev/null/x", ""])
def test_verification_out_that_cannot_be_created(capsys, out):
    """Was a NotADirectoryError traceback; an empty --out ran the section into the current directory."""
    assert_refused(verification_main, ["paper", "--quick", "--out", out, "--no-progress"], capsys, "--out")


def test_printed_results_never_contain_nan(capsys):
    """Every CLI prints through print_result: a non-finite number (e.g. converge's observed order fitted from fewer
    than two points) is null in JSON, not the invalid token NaN."""
    from sinterheat.cli import print_result

    print_result({"order": float("nan"), "K": [1.5, float("inf")], "nested": {"x": -float("inf")}}, as_json=True)
    out = capsys.readouterr().out
    assert json.loads(out) == {"order": None, "K": [1.5, None], "nested": {"x": None}}
    assert "NaN" not in out and "Infinity" not in out


def test_fit_file_with_nan_parameters_named(tmp_path, capsys):
    """A fit.json whose law has a NaN parameter gave NaN conductances, reported as a 'numerically singular' system."""
    import pathlib

    import fem_neck

    data = json.loads((pathlib.Path(fem_neck.__file__).parent / "data" / "fit.json").read_text())
    data["law"]["parameters"]["A"] = float("nan")
    fit = tmp_path / "fit.json"
    fit.write_text(json.dumps(data))
    refuse_scene(tmp_path, scene(extra=f'[conductance]\nlaw = "fit"\nfit_file = "{fit}"\n'), capsys,
                 "fit_file", "finite")
