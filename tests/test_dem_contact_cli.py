"""``python -m dem contact``: one Luding 2005 pair contact through a prescribed history; the ``[contact]`` scene
table and the built-in ``luding-table1`` scene."""

import csv
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from dem.cli import main
from dem.laws.contact.luding import LUDING_TABLE1 as MAT
from dem.scene.parse import builtin_scenes, load_scene, luding_material_from_scene, parse_scene

K1, K2, KC = MAT.k1, MAT.k2, MAT.kc
A = float(np.mean(load_scene("luding-table1").particles.radius))  # 300 random radii in 1 mm (1 +- 0.5)
DMF = K2 * MAT.fluid_overlap * A / (K2 - K1)

HISTORY = """t,overlap,T
0.0,0.0,80
1.0,1e-5,80
2.0,2e-5,80
3.0,1e-5,80
4.0,1e-5,130
5.0,-1e-6,130
6.0,1e-6,130
"""


def s_of(T):
    """k1(T)/k1, eq. (10) as printed."""
    return 0.5 * (1.0 + math.tanh((MAT.T_melt - T) / MAT.T_var))


def k2_hand(dmax):
    return K2 if dmax >= DMF else K1 + (K2 - K1) * dmax / DMF


def run_cli(capsys, *args):
    code = main(["contact", *args])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def history(tmp_path):
    path = tmp_path / "history.csv"
    path.write_text(HISTORY)
    return path


def test_json_rows_follow_the_law_by_hand(capsys, history):
    code, out, err = run_cli(capsys, "luding-table1", "--history", str(history), "--json")
    assert code == 0, err
    r = json.loads(out)
    names = ("t", "overlap", "T", "force", "delta_max", "delta_0", "k1", "k2", "kc", "f_min")
    assert all(len(r[k]) == 7 for k in names)
    assert r["radius"] == A and r["delta_fluid"] == pytest.approx(0.2 * A) and r["damping"] is True
    assert "mean radius" in r["pair"]
    s = s_of(80.0)
    g = MAT.gamma_n
    # loading at 80 C on k1(T) delta, plus gamma_0 times the backward difference (1e-5 m/s)
    assert r["force"][0] == 0.0
    assert r["force"][1] == pytest.approx(s * K1 * 1e-5 + g * 1e-5, rel=1e-12)
    assert r["force"][2] == pytest.approx(s * K1 * 2e-5 + g * 1e-5, rel=1e-12)
    assert r["k1"][2] == pytest.approx(s * K1, rel=1e-12)
    k2m = k2_hand(2e-5)
    d0 = (1 - s * K1 / k2m) * 2e-5
    assert (r["delta_max"][2], r["k2"][2]) == (2e-5, pytest.approx(k2m, rel=1e-14))
    assert r["delta_0"][2] == pytest.approx(d0, rel=1e-12)
    assert r["kc"][2] == pytest.approx(s * k2m / K2 * KC, rel=1e-13)
    kc = s * k2m / K2 * KC
    assert r["f_min"][2] == pytest.approx(-(k2m - s * K1) / (1 + k2m / kc) * 2e-5, rel=1e-12)
    # unloading on the k2 line
    assert r["force"][3] == pytest.approx(k2m * (1e-5 - d0) - g * 1e-5, rel=1e-12)
    # heating to 130 C for 1 s: k1(T, t) relaxes by eq. (11) (t0 = 1e3 s), delta_max kept, delta_0 grows
    K = s_of(130.0)
    s4 = K * (1 - 1 / (1 / (1 - s / K) - 1.0 / MAT.t0))
    assert r["k1"][4] == pytest.approx(s4 * K1, rel=1e-12)
    assert r["delta_max"][4] == 2e-5 and r["delta_0"][4] == pytest.approx((1 - s4 * K1 / k2m) * 2e-5, rel=1e-12)
    assert r["force"][4] == pytest.approx(k2m * (1e-5 - r["delta_0"][4]), rel=1e-12)
    # the contact opens (no force, no history) and a new one starts on the loading line
    assert (r["force"][5], r["delta_max"][5], r["delta_0"][5]) == (0.0, 0.0, 0.0)
    assert r["delta_max"][6] == 1e-6 and r["force"][6] == pytest.approx(r["k1"][6] * 1e-6 + g * 2e-6, rel=1e-12)


def test_no_damping_csv_and_png(capsys, history, tmp_path):
    out_dir = tmp_path / "out"
    code, out, err = run_cli(capsys, "luding-table1", "--history", str(history), "--no-damping", "--out",
                             str(out_dir))
    assert code == 0, err
    assert "mean radius" in out and "force" in out.splitlines()[0]  # the table, then the summary lines
    with open(out_dir / "contact.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == ["t", "overlap", "T", "force", "delta_max", "delta_0", "k1", "k2", "kc", "f_min"]
    assert len(rows) == 7
    assert float(rows[1]["force"]) == pytest.approx(s_of(80.0) * K1 * 1e-5, rel=1e-14)
    assert (out_dir / "contact.png").stat().st_size > 10_000


def test_fig2_cycle_through_the_tension_branch(capsys, tmp_path):
    """Loading, unloading past delta_min onto -kc delta, reloading on a new k2 line to the k1 line."""
    path = tmp_path / "cycle.csv"
    path.write_text("t,overlap,T\n0,1e-4,20\n1,2e-6,20\n2,1.5e-5,20\n3,1.2e-4,20\n")
    code, out, err = run_cli(capsys, "luding-table1", "--history", str(path), "--no-damping", "--json")
    assert code == 0, err
    r = json.loads(out)
    s = s_of(20.0)
    assert r["force"][1] == pytest.approx(-r["kc"][1] * 2e-6, rel=1e-12)
    assert r["delta_0"][1] == pytest.approx(2e-6 * (1 + s * KC / K2), rel=1e-12) and r["delta_max"][1] < 1e-4
    assert r["force"][2] == pytest.approx(r["k2"][1] * (1.5e-5 - r["delta_0"][1]), rel=1e-10)
    assert r["force"][3] == pytest.approx(s * K1 * 1.2e-4, rel=1e-12) and r["delta_max"][3] == 1.2e-4


BAD = {
    "missing column": ("t,overlap\n0,1e-5\n", "column 'T' missing"),
    "t not increasing": ("t,overlap,T\n0,1e-5,20\n1,2e-5,20\n1,1e-5,20\n", "row 3: t = 1.0"),
    "nan": ("t,overlap,T\n0,1e-5,20\n1,nan,20\n", "row 2: overlap = 'nan': must be finite"),
    "text": ("t,overlap,T\n0,1e-5,hot\n", "row 1: T = 'hot': must be a number"),
    "empty cell": ("t,overlap,T\n0,,20\n", "row 1: overlap = ''"),
    "no rows": ("t,overlap,T\n", "no data rows"),
    "empty file": ("", "column 't' missing"),
    "radius vanishes": ("t,overlap,T\n0,1e-5,-1e5\n", "T_melt - 1/expansion"),
    "overlap beyond the pair": ("t,overlap,T\n0,1e-5,20\n1,0.5,20\n", "row 2: overlap = 0.5 m: valid range overlap "
                                f"< 2 a = {2 * A:.6g} m"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_history_exits_2_with_one_line(capsys, tmp_path, case):
    text, words = BAD[case]
    path = tmp_path / "bad.csv"
    path.write_text(text)
    code, out, err = run_cli(capsys, "luding-table1", "--history", str(path), "--json")
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and words in err, err


def test_missing_file_and_scene_without_luding_material(capsys, history, tmp_path):
    code, out, err = run_cli(capsys, "luding-table1", "--history", str(tmp_path / "none.csv"))
    assert code == 2 and "no such file" in err and len(err.strip().splitlines()) == 1
    code, out, err = run_cli(capsys, "pair", "--history", str(history))
    assert code == 2 and "no [contact] table" in err and len(err.strip().splitlines()) == 1


@pytest.mark.slow
def test_real_command_line(history):
    proc = subprocess.run([sys.executable, "-m", "dem", "contact", "luding-table1", "--history", str(history),
                           "--json"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert len(json.loads(proc.stdout)["force"]) == 7


# ------------------------------------------------------------------------------------------ [contact] table
def scene_doc(**contact):
    table = {"law": "luding", **{k: getattr(MAT, k) for k in ("k1", "k2", "kc", "kt_ratio", "gamma_n", "gamma_t",
                                                             "mu", "mu_wall", "T_melt", "T_var", "expansion",
                                                             "fluid_overlap", "t0", "brittle_sliding",
                                                             "wall_sintering")}}
    table.update(contact)
    return {"scene": {"physics": ["mechanical"]}, "material": {"density": 2000.0},
            "particles": {"position": [[0.0, 0.0, 0.0]], "radius": [1e-3], "temperature": [20.0]},
            "contact": {k: v for k, v in table.items() if v is not None},
            "solver": {"mode": "transient", "t_end": 1e-3}}


def test_builtin_scene_carries_table1():
    assert "luding-table1" in builtin_scenes()
    scene = load_scene("luding-table1")
    assert scene.contact == MAT and luding_material_from_scene(scene) == MAT
    assert sum(scene.particles.radius) / scene.particles.n == pytest.approx(A, rel=1e-15)


def test_contact_table_density_from_material_and_from_a_dict():
    assert luding_material_from_scene(scene_doc()) == MAT
    assert parse_scene(scene_doc()).contact == MAT
    assert luding_material_from_scene(scene_doc(density=1000.0)).density == 1000.0
    static = {k: v for k, v in scene_doc().items() if k not in ("contact", "scene", "solver")}
    static["material"] = {"conductivity": 0.25, "density": 2000.0, "specific_heat": 1700.0}
    assert parse_scene(static).contact is None
    with pytest.raises(ValueError, match=r"\[contact\]: not read by the static engine"):
        parse_scene({**static, "contact": scene_doc()["contact"]})


@pytest.mark.parametrize("edit, words", [
    ({"law": "hertz"}, "[contact] law = 'hertz'"),
    ({"k1": None}, "[contact] k1: required"),
    ({"k1": 3e5}, "[contact] k1 = 300000.0: must be <= k2"),
    ({"fluid_overlap": 1.5}, "[contact] fluid_overlap = 1.5: must be in (0, 1)"),
    ({"mu": "high"}, "[contact] mu = 'high': must be a finite number"),
    ({"brittle_sliding": "yes"}, "[contact] brittle_sliding = 'yes': must be true or false"),
    ({"stiffness": 1.0}, '[contact] stiffness: not a parameter of law = "luding"'),
])
def test_contact_table_errors_name_the_key(edit, words):
    with pytest.raises(ValueError) as info:
        parse_scene(scene_doc(**edit))
    assert words in str(info.value), str(info.value)
