"""Corrupt inputs get one line naming the file: an empty, truncated or foreign ``[start] state`` or
``checkpoint.npz`` (they raised ``EOFError`` and ``BadZipFile`` tracebacks), a VTK file declaring 10^9 points but
holding 2 (a stray ``ERROR:root:`` line, then "holds no points"), a ``fit_file`` of binary garbage ("'utf-8' codec
can't decode", naming no file)."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from dem.cli import main as dem_main
from dem.output.atomic import read_npz
from dem.scene import state_file
from test_cli_stress import run_cli
from test_run_folder_faults import PAIR_TOML

MATERIAL = "[material]\nconductivity = 394.0\ndensity = 8960.0\nspecific_heat = 385.0\n"
STEADY = '[solver]\nmode = "steady"\nfloating = "mean"\n'


def corrupt_copies(good, tmp_path) -> dict:
    """Empty, truncated, garbage and foreign (a .npz of other arrays, a .npy) versions of the .npz ``good``."""
    data = good.read_bytes()
    files = {"empty": b"", "truncated": data[: len(data) // 2], "garbage": bytes(range(256)) * 8}
    out = {}
    for name, content in files.items():
        out[name] = tmp_path / f"{name}.npz"
        out[name].write_bytes(content)
    out["foreign"] = tmp_path / "foreign.npz"
    np.savez(out["foreign"], weights=np.ones(3))
    out["npy"] = tmp_path / "array.npz"
    with out["npy"].open("wb") as fh:
        np.save(fh, np.ones(3))
    return out


def saved_state(tmp_path):
    x = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 3.94e-3]])
    return state_file.save({"engine": np.array("static"), "t": np.array(0.0), "steps": np.array(0), "x": x,
                            "radius": np.array([1e-3, 3e-3]), "T": np.array([100.0, 0.0]), "id": np.arange(2),
                            "material": np.zeros(2, dtype=np.int32)}, tmp_path / "state.npz")


@pytest.mark.parametrize("kind", ["empty", "truncated", "garbage", "foreign", "npy"])
def test_a_corrupt_start_state_is_one_line_naming_the_file(tmp_path, capsys, kind):
    bad = corrupt_copies(saved_state(tmp_path), tmp_path)[kind]
    with pytest.raises(ValueError, match=r"^\[start\] state = '.*%s'" % bad.name):
        state_file.load(bad)
    scene = tmp_path / "scene.toml"
    scene.write_text(MATERIAL + f'[start]\nstate = "{bad}"\n' + STEADY)
    code, out, err = run_cli(dem_main, ["run", str(scene), "--json"], capsys)
    assert code == 2 and out == "" and len(err) == 1 and bad.name in err[0], err


@pytest.mark.parametrize("kind", ["empty", "truncated", "garbage", "npy"])
@pytest.mark.slow
def test_a_corrupt_checkpoint_is_one_line_on_resume(tmp_path, capsys, kind):
    scene = tmp_path / "pair.toml"
    scene.write_text(PAIR_TOML)
    out = tmp_path / "run"
    assert run_cli(dem_main, ["run", str(scene), "--out", str(out), "--quiet"], capsys)[0] == 0
    summary = json.loads((out / "summary.json").read_text())
    summary["interrupted"] = True  # as a run stopped before its end leaves it
    (out / "summary.json").write_text(json.dumps(summary))
    shutil.copy(corrupt_copies(out / "checkpoint.npz", tmp_path)[kind], out / "checkpoint.npz")
    code, stdout, err = run_cli(dem_main, ["run", str(scene), "--out", str(out), "--resume", "--quiet"], capsys)
    assert code == 2 and stdout == "" and len(err) == 1, err
    assert "checkpoint.npz" in err[0] and "cannot be read" in err[0], err


def test_read_npz_reads_a_whole_file(tmp_path):
    np.savez(tmp_path / "a.npz", x=np.arange(3.0))
    assert np.array_equal(read_npz(tmp_path / "a.npz", "test")["x"], np.arange(3.0))


@pytest.mark.parametrize("suffix, text", [
    (".vtk", "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS 1000000000 float\n0 0 0\n1 0 0\n"),
    (".vtu", '<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">\n'
             '<UnstructuredGrid>\n<Piece NumberOfPoints="1000000000" NumberOfCells="0">\n<Points>\n'
             '<DataArray type="Float64" NumberOfComponents="3" format="ascii">0 0 0 1 0 0</DataArray>\n</Points>\n'
             "</Piece>\n</UnstructuredGrid>\n</VTKFile>\n"),
])
def test_a_vtk_file_declaring_more_points_than_it_holds(tmp_path, capfd, suffix, text):
    packing = tmp_path / f"big{suffix}"
    packing.write_text(text)
    scene = tmp_path / "scene.toml"
    scene.write_text(MATERIAL + f'[particles]\nfile = "{packing}"\n' + STEADY)
    code = dem_main(["run", str(scene), "--json"])
    out, err = capfd.readouterr()  # the file descriptors: VTK and logging write there too
    lines = [line for line in err.splitlines() if line.strip()]
    assert code == 2 and out == "" and len(lines) == 1, err
    assert packing.name in lines[0] and "cannot be read as VTK" in lines[0], err


def test_a_garbage_fit_file_is_named(tmp_path, capsys):
    garbage = tmp_path / "fit.json"
    garbage.write_bytes(bytes(range(128, 256)) * 4)
    scene = tmp_path / "scene.toml"
    scene.write_text(PAIR_TOML + f'[conductance]\nlaw = "fit"\nfit_file = "{garbage}"\n')
    code, out, err = run_cli(dem_main, ["run", str(scene), "--json"], capsys)
    assert code == 2 and out == "" and len(err) == 1, err
    assert "fit.json" in err[0] and "cannot be read as JSON" in err[0] and "codec" not in err[0], err
