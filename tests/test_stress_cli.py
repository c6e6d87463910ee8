"""CLI abuse: ``python -m fem_neck`` and ``python -m dem run`` in real subprocesses, with bad or extreme input.

Every run must end in exit code 2 with one line on stderr, or exit 0 with finite output (one JSON object with
``--json``) -- never a traceback, NaN/Infinity in the output, or a hang. Marked ``stress``; all but a handful are
also ``slow`` (each is a fresh interpreter): ``python -m pytest -m stress`` runs them all. The in-process regression
tests of the same CLIs are in ``test_cli_stress.py``.
"""

from __future__ import annotations

import json
import pathlib
import subprocess
import sys

import pytest

pytestmark = pytest.mark.stress


def is_progress(line: str) -> bool:
    return "it/s]" in line or "s/it]" in line or "%|" in line


def cli_outcome(argv: list[str], expect: str = "error", timeout: float = 120.0, cwd=None) -> tuple[bool, str]:
    """Run ``python -m <argv>``; ``expect`` is ``"error"`` (exit 2, one line on stderr), ``"ok"`` (exit 0, finite
    JSON when ``--json``) or ``"either"``. Returns ``(passed, what happened in one line)``."""
    try:
        proc = subprocess.run([sys.executable, "-m", *argv], capture_output=True, text=True, timeout=timeout, cwd=cwd)
    except subprocess.TimeoutExpired:
        return False, f"hang: no exit within {timeout:g} s"
    err_lines = [ln for ln in proc.stderr.splitlines() if ln.strip() and not is_progress(ln)]
    if "Traceback" in proc.stderr:
        return False, f"exit {proc.returncode} with a traceback: {err_lines[-1] if err_lines else ''}"[:300]
    if proc.returncode == 2:
        one = len(err_lines) == 1
        msg = err_lines[0] if err_lines else "(empty stderr)"
        return expect in ("error", "either") and one, (
            f"exit 2: {msg}"[:300] + ("" if one else f" (+{len(err_lines) - 1} more stderr lines)"))
    if proc.returncode == 0:
        if any(tok in proc.stdout for tok in ("NaN", "nan,", "Infinity", " inf")):
            return False, "exit 0 but NaN/Infinity in the output"
        if "--json" in argv:
            try:
                json.loads(proc.stdout)
            except json.JSONDecodeError:
                return False, "exit 0 but stdout is not one JSON object"
        return expect in ("ok", "either"), f"exit 0: {proc.stdout.strip()[:200]}"
    return False, f"exit {proc.returncode}: {(err_lines[-1] if err_lines else proc.stdout.strip())[:250]}"


def check(argv, expect="error", timeout=120.0) -> str:
    passed, outcome = cli_outcome(argv, expect, timeout)
    assert passed, outcome
    return outcome


# ------------------------------------------------------------------------------------------------- in the default run
@pytest.mark.parametrize("argv", [
    ["fem_neck", "neck", "--ri", "nan", "--rj", "1e-3", "--h", "1e-5", "--json"],
    ["fem_neck", "semisphere", "--h-over-r", "0.7", "--json"],
    ["fem_neck", "semisphere", "--h-over-r", "0.1", "--rtol", "0", "--json"],
    ["fem_neck", "pair", "--ri", "1e-3", "--rj", "-3e-3", "--h", "6e-5", "--kappa", "394", "--json"],
    ["dem", "run", "no-such-scene", "--json"],
])
@pytest.mark.slow
def test_cli_bad_input_is_one_line_exit_2(argv):
    check(argv, "error")


def test_neck_cli_huge_radii():
    check(["fem_neck", "neck", "--ri", "1e300", "--rj", "1e300", "--h", "1e299", "--json"], "either")


def test_semisphere_neck_below_supported_range_explained():
    outcome = check(["fem_neck", "semisphere", "--a-over-r", "5e-5", "--json"], "error")
    assert "a_over_r" in outcome, outcome


@pytest.mark.slow
def test_dem_generator_huge_n_refused(tmp_path: pathlib.Path):
    scene = tmp_path / "huge.toml"
    scene.write_text('[material]\nconductivity = 394.0\ndensity = 8960.0\nspecific_heat = 385.0\n'
                     '[generator]\nkind = "random"\nn = 1000000000000\nradius = 5e-5\noverlap = 0.1\n'
                     'boundary = "plates"\nhot = 1.0\ncold = 0.0\n[conductance]\nlaw = "rojek"\n'
                     '[solver]\nmode = "steady"\nfloating = "mean"\n')
    proc = subprocess.run([sys.executable, "-m", "dem", "run", str(scene), "--json"], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr[-300:]


@pytest.mark.parametrize("argv", [["fem_neck", "semisphere", "--h-over-r", "0.2"], ["dem", "run", "pair"]])
@pytest.mark.slow
def test_out_is_an_existing_file(tmp_path: pathlib.Path, argv):
    afile = tmp_path / "afile"
    afile.write_text("")
    check(argv + ["--out", str(afile), "--json"], "error")


@pytest.mark.slow
def test_out_that_cannot_be_created_is_named(tmp_path: pathlib.Path):
    afile = tmp_path / "afile"
    afile.write_text("")
    outcome = check(["dem", "run", "pair", "--out", str(afile / "run"), "--json"], "error")
    assert f"--out {afile / 'run'}: cannot be created" in outcome, outcome
    # where a command meets the file system's error itself, the one line names the option or the path given
    outcome = check(["fem_neck", "semisphere", "--h-over-r", "0.2", "--out", str(afile / "x"), "--json"], "error")
    assert f"--out {afile / 'x'}: Not a directory" in outcome, outcome
    outcome = check(["dem", "convert", "pair", str(afile / "x.csv")], "error")
    assert f": error: {afile / 'x.csv'}: Not a directory" in outcome, outcome


# -------------------------------------------------------------------------------------------------- python -m fem_neck
FEM_NECK = [
    ("neck: NaN radius", ["neck", "--ri", "nan", "--rj", "1e-3", "--h", "1e-5", "--json"], "error"),
    ("neck: negative radius", ["neck", "--ri", "-1e-3", "--rj", "1e-3", "--h", "1e-5", "--json"], "error"),
    ("neck: text radius", ["neck", "--ri", "abc", "--rj", "1e-3", "--h", "1e-5"], "error"),
    ("neck: overlap beyond range", ["neck", "--ri", "1e-3", "--rj", "1e-3", "--h", "1e-3", "--json"], "error"),
    ("neck: missing option", ["neck", "--ri", "1e-3"], "error"),
    ("neck: unknown method", ["neck", "--ri", "1", "--rj", "1", "--h", "0.1", "--method", "x"], "error"),
    ("neck: radius ratio 1e6", ["neck", "--ri", "1e-9", "--rj", "1e-3", "--h", "1e-10", "--json"], "either"),
    ("neck: radii 1e600 apart (a sphere on a plane: answered, no overflow)",
     ["neck", "--ri", "1e-300", "--rj", "1e300", "--h", "1e-301", "--json"], "ok"),
    ("semisphere: NaN", ["semisphere", "--h-over-r", "nan", "--json"], "error"),
    ("semisphere: negative", ["semisphere", "--h-over-r", "-0.1", "--json"], "error"),
    ("semisphere: rtol negative", ["semisphere", "--h-over-r", "0.1", "--rtol", "-1", "--json"], "error"),
    ("semisphere: rtol 1e-14", ["semisphere", "--h-over-r", "0.1", "--rtol", "1e-14", "--json"], "either"),
    ("semisphere: rtol 10", ["semisphere", "--h-over-r", "0.1", "--rtol", "10", "--json"], "either"),
    ("semisphere: h/r 1e-9", ["semisphere", "--h-over-r", "1e-9", "--json"], "either"),
    ("pair: kappa 0", ["pair", "--ri", "1e-3", "--rj", "3e-3", "--h", "6e-5", "--kappa", "0", "--json"], "error"),
    ("pair: h beyond range", ["pair", "--ri", "1e-3", "--rj", "3e-3", "--h", "1e-3", "--kappa", "394", "--json"],
     "error"),
    ("chain: lengths disagree", ["chain", "--radii", "1e-3,1e-3,1e-3", "--overlaps", "1e-4", "--kappa", "394",
                                 "--json"], "error"),
    ("chain: empty radii", ["chain", "--radii", "", "--overlaps", "", "--kappa", "394", "--json"], "error"),
    ("chain: garbage list", ["chain", "--radii", "1e-3,x", "--overlaps", "1e-4", "--kappa", "394"], "error"),
    ("chain: 200 spheres (refused up front, not a 10-minute solve)",
     ["chain", "--radii", ",".join(["1e-3"] * 200), "--overlaps", ",".join(["1e-4"] * 199), "--kappa", "394",
      "--json"], "error"),
    ("fit: 10^12 points (refused before allocating)", ["fit", "--points", "1000000000000", "--json"], "error"),
    ("fit: zero points", ["fit", "--points", "0", "--json"], "error"),
    ("fit: negative points", ["fit", "--points", "-5", "--json"], "error"),
    ("unknown command", ["frobnicate"], "error"),
]


@pytest.mark.slow
@pytest.mark.parametrize("argv, expect", [case[1:] for case in FEM_NECK], ids=[case[0] for case in FEM_NECK])
def test_fem_neck_cli(argv, expect):
    check(["fem_neck", *argv], expect)


@pytest.fixture
def cluster_file(tmp_path):
    path = tmp_path / "cluster.json"
    path.write_text(json.dumps({"centres": [[0, 0, 0], [0, 0, 1.92e-3]], "radii": [1e-3, 1e-3],
                                "bonds": [[0.5, 1]], "terminals": [{"particle": 0, "T": 1.0},
                                                                   {"particle": 1, "T": 0.0}]}))
    return path


@pytest.mark.slow
@pytest.mark.parametrize("options", [[], ["--size-far", "1e-300"]], ids=["fractional bond index", "size-far 1e-300"])
def test_fem_neck_cluster_cli(cluster_file, options):
    check(["fem_neck", "cluster", str(cluster_file), *options, "--json"], "error")


# -------------------------------------------------------------------------------------------------- python -m dem run
SCENE_OK = """
[material]
conductivity = 394.0
density = 8960.0
specific_heat = 385.0
[particles]
position = [[0.0, 0.0, 0.0], [0.0, 0.0, 3.94e-3]]
radius = [1.0e-3, 3.0e-3]
temperature = [100.0, 0.0]
[conductance]
law = "rojek"
[solver]
mode = "transient"
integrator = "{integrator}"
dt = {dt}
t_end = {t_end}
"""
BASE = SCENE_OK.format(integrator="implicit", dt="1.0e-3", t_end="0.01")
GENERATED = BASE.split("[particles]")[0] + """[generator]
kind = "random"
n = {n}
radius = 5.0e-5
overlap = {overlap}
seed = 1
boundary = "plates"
hot = 1.0
cold = 0.0
[conductance]
law = "rojek"
[solver]
mode = "steady"
floating = "mean"
"""
BAD_SCENES = {  # refused: exit 2 with one line
    "malformed TOML": BASE.replace("radius = [", "radius = [[", 1),
    "unknown key": BASE.replace("[conductance]", "[conductance]\nfoo = 1"),
    "unknown section": BASE + "\n[bogus]\nx = 1\n",
    "missing conductivity": BASE.replace("conductivity = 394.0\n", ""),
    "negative radius": BASE.replace("radius = [1.0e-3", "radius = [-1.0e-3"),
    "NaN radius": BASE.replace("radius = [1.0e-3", "radius = [nan"),
    "NaN temperature": BASE.replace("temperature = [100.0", "temperature = [nan"),
    "inf temperature": BASE.replace("temperature = [100.0", "temperature = [inf"),
    "lengths disagree": BASE.replace("radius = [1.0e-3, 3.0e-3]", "radius = [1.0e-3]"),
    "empty particle list": BASE.replace("position = [[0.0, 0.0, 0.0], [0.0, 0.0, 3.94e-3]]", "position = []")
    .replace("radius = [1.0e-3, 3.0e-3]", "radius = []").replace("temperature = [100.0, 0.0]", "temperature = []"),
    "position not 3D": BASE.replace("[0.0, 0.0, 3.94e-3]]", "[0.0, 3.94e-3]]"),
    "overlap beyond neck range": BASE.replace("3.94e-3]]", "2.1e-3]]"),
    "coincident particles": BASE.replace("3.94e-3]]", "0.0]]"),
    "negative dt": BASE.replace("dt = 1.0e-3", "dt = -1.0e-3"),
    "zero dt": BASE.replace("dt = 1.0e-3", "dt = 0.0"),
    "dt as text": BASE.replace("dt = 1.0e-3", 'dt = "fast"'),
    "negative t_end": BASE.replace("t_end = 0.01", "t_end = -1.0"),
    "unknown integrator": BASE.replace('integrator = "implicit"', 'integrator = "rk4"'),
    "unknown law": BASE.replace('law = "rojek"', 'law = "magic"'),
    "unknown mode": BASE.replace('mode = "transient"', 'mode = "quasi"'),
    "negative density": BASE.replace("density = 8960.0", "density = -8960.0"),
    "explicit dt 1e3x the limit": SCENE_OK.format(integrator="explicit", dt="1.0", t_end="10.0"),
    "steady without fixed temperature": BASE.replace('mode = "transient"', 'mode = "steady"'),
    "generator n = 0": GENERATED.format(n=0, overlap=0.1),
    "generator n = 1e12": GENERATED.format(n="1000000000000", overlap=0.1),
    "generator n = 2.5": GENERATED.format(n=2.5, overlap=0.1),
    "generator overlap 0.7 (beyond 2/3)": GENERATED.format(n=100, overlap=0.7),
    "generator overlap negative": GENERATED.format(n=100, overlap=-0.1),
    "chain generator overlap 5 (was: no bonds)": GENERATED.format(n=3, overlap=5.0).replace('"random"', '"chain"')
    .replace("seed = 1\n", ""),
    "lattice shape overflowing int64": GENERATED.replace('kind = "random"\nn = {n}', 'kind = "lattice"\nshape = '
                                                         '[9223372036854775807, 2, 2]').replace("seed = 1\n", "")
    .format(overlap=0.1),
    "radiation negative emissivity": BASE + "\n[radiation]\nemissivity = -0.5\nT_inf = 20.0\n",
    "convection NaN h": BASE + "\n[convection]\nh = nan\nT_inf = 20.0\n",
    "duplicate key": BASE.replace("t_end = 0.01", "t_end = 0.01\nt_end = 0.02"),
    "binary garbage": "\x00\x01\x02 = [[[",
    "radiation with a temperature below absolute zero": BASE.replace("temperature = [100.0", "temperature = [-400.0")
    + '\n[radiation]\nemissivity = 0.5\nT_inf = 20.0\nunit = "C"\n',
    "radiation ambient at 1e80 K (was NaN)": BASE.replace('mode = "transient"', 'mode = "steady"')
    + "\n[radiation]\nemissivity = 1.0\nT_inf = 1e80\n",
    "text for a number (slope)": BASE.replace('law = "rojek"', 'law = "rojek"\nslope = "x"'),
    "conductivity 1e300": BASE.replace("conductivity = 394.0", "conductivity = 1e300"),
    "temperatures +-1e308": BASE.replace("temperature = [100.0, 0.0]", "temperature = [1e308, -1e308]"),
    "lens clip, coincident particles": BASE.replace("3.94e-3]]", "0.0]]").replace(
        'law = "rojek"', 'law = "zohdi"\nout_of_range = "clip"'),
    "lens clip, centre behind a wall": BASE.replace('law = "rojek"', 'law = "zohdi"\nout_of_range = "clip"')
    + "\n[[walls]]\npoint = [0.0, 0.0, 0.5e-3]\nnormal = [0.0, 0.0, 1.0]\ntemperature = 1.0\n",
    "rtol 1e-300 with dt auto": BASE.replace("dt = 1.0e-3", 'dt = "auto"\nrtol = 1e-300'),
    "1e6 fixed steps (default max_steps 1e5)": BASE.replace("dt = 1.0e-3", "dt = 1.0e-5").replace(
        "t_end = 0.01", "t_end = 10.0"),
}
LONG_RUNS = {  # answered or refused, but never a hang, a NaN or a traceback
    "generator single particle, steady": GENERATED.format(n=1, overlap=0.1),
    "radiation, explicit auto": SCENE_OK.format(integrator="explicit", dt='"auto"', t_end="1.0")
    + "\n[radiation]\nemissivity = 1.0\nT_inf = 20.0\n",
    "implicit auto, t_end 1e6 s": SCENE_OK.format(integrator="implicit", dt='"auto"', t_end="1.0e6"),
    # would take ~1e12 steps: must be refused or capped
    "explicit t_end 1e9 s": SCENE_OK.format(integrator="explicit", dt="1.0e-6", t_end="1.0e9"),
    "lens clip, sphere inside a sphere": BASE.replace("3.94e-3]]", "1.0e-4]]").replace(
        "radius = [1.0e-3, 3.0e-3]", "radius = [1.0e-3, 1.0e-5]").replace(
        'law = "rojek"', 'law = "zohdi"\nout_of_range = "clip"'),
    "singular implicit step (capacities 1e-56 J/K, dt 1e6 s)": SCENE_OK.format(
        integrator="implicit", dt="1.0e6", t_end="1.0e6").replace("conductivity = 394.0", "conductivity = 1e10")
    .replace("density = 8960.0", "density = 1e-10").replace("specific_heat = 385.0", "specific_heat = 1e-10")
    .replace("[[0.0, 0.0, 0.0], [0.0, 0.0, 3.94e-3]]", "[[0.0, 0.0, 0.0], [0.0, 0.0, 1.9e-12]]")
    .replace("radius = [1.0e-3, 3.0e-3]", "radius = [1.0e-12, 1.0e-12]"),
}


def write(path: pathlib.Path, text: str) -> pathlib.Path:
    path.write_text(text)
    return path


@pytest.mark.slow
@pytest.mark.parametrize("name", list(BAD_SCENES) + list(LONG_RUNS))
def test_dem_cli_scene(tmp_path, name):
    scene = write(tmp_path / "scene.toml", BAD_SCENES.get(name) or LONG_RUNS[name])
    check(["dem", "run", str(scene), "--json", "--out", str(tmp_path / "out")],
          "error" if name in BAD_SCENES else "either", timeout=60.0)


@pytest.mark.slow
@pytest.mark.parametrize("case", ["missing scene file", "scene is a directory", "no arguments",
                                  "--out is an existing file"])
def test_dem_cli_bad_invocation(tmp_path, case):
    good = write(tmp_path / "good.toml", BASE)
    argv = {"missing scene file": ["run", str(tmp_path / "nope.toml"), "--json"],
            "scene is a directory": ["run", str(tmp_path), "--json"],
            "no arguments": [],
            "--out is an existing file": ["run", str(good), "--json", "--out", str(write(tmp_path / "afile", ""))]}
    check(["dem", *argv[case]], "error")


@pytest.mark.slow
def test_dem_cli_good_scene_runs(tmp_path):
    check(["dem", "run", str(write(tmp_path / "good.toml", BASE)), "--json", "--out", str(tmp_path / "out")], "ok")
