"""The console blocks of the README and of the documentation's pages (``docs/**/*.md``), run: every ```` ```console ````
block's ``$ `` commands run in a fresh folder, and every number they print must match the page's.

Tolerance: relative 1e-6 (and absolute 1e-12 for numbers at round-off level, such as an energy error of 5e-17). An
``energy_error`` below ``ENERGY_ROUND_OFF`` reads as 0: it is relative to a scale never taken below the square root
of the machine precision times the gross flows (``dem.network.heat.BalanceScales.flow_magnitude``), so where no net
heat flows through the balance, round-off of the flows reads as a few times 1e-8 (a 12-particle bed whose middle
layer sits at the mean of its neighbours gives 0 on the machine that wrote its page and 5e-9 on another, where
numpy 2.3 or 2.4, numba 0.68.0 or 0.68.1, other OpenBLAS kernels and numpy without AVX2 all give 5e-9: which
round-off differs was not isolated). Two figures of
``fem_neck converge`` are made of errors near round-off and are compared to ``KEY_RTOL``: the hp levels' error
ratio and the reference's error estimate (about 2e-10), which the BLAS kernels a processor selects move by up to
3e-6 and 4e-3 (``OPENBLAS_CORETYPE=Prescott`` against the host's kernels on one machine; 2.5e-5 and 1e-3 between
two machines).
Every command shown is deterministic (seeded, fixed meshes, no timing-dependent choices), so on the machine that
wrote the README the numbers agree to all printed digits; 1e-6 leaves room for platform round-off amplified by the
solves (BLAS, libm, SuperLU orderings) while staying 100x tighter than the loosest solver tolerance shown (rtol
1e-4), so a changed algorithm or a stale README fails. Timings are ignored: ``seconds`` and ``*_seconds`` entries,
and numbers with the unit ``s`` (``1.8 s``). Commands are run with ``python`` replaced by this interpreter, the
repository on ``PYTHONPATH``, and stdout and stderr together, as a terminal shows them (progress bars left out).
Input files the page shows (a fenced block right after ``<!-- file: NAME -->``) are written into the folder first. A
command shown with the same output (and the same files it names) on several pages runs once, for all of them.
"""

from __future__ import annotations

import json
import math
import os
import pathlib
import re
import shlex
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
PAGES = [README, *sorted(p for p in (ROOT / "docs").rglob("*.md") if "_build" not in p.parts)]
RTOL, ATOL = 1e-6, 1e-12
ENERGY_ROUND_OFF = 1e-7  # an energy_error below it is round-off (module docstring)
KEY_RTOL = {"hp_error_ratio_per_order": 1e-4, "reference_error_estimate": 1e-2}  # (module docstring)
# commands of more than a few seconds, or that compile kernels of their own in a fresh clone (the neck-node elements,
# 40 s, beside a quick test compiling them too; the Trefftz element's): marked slow
SLOW = ("fem_neck converge", "fem_neck lattice", "fem_neck cluster", "verification", "dem run fcc.toml",
        "dem run law.toml", "dem run trefftz.toml", "fem_neck unequal")
NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")
TIMING = re.compile(r"(?<![\w.])\d+(?:\.\d+)?\s?s\b")  # "1.8 s": a wall time in a table
# a tqdm bar on stderr (a terminal overwrites it in place): its percentage, its rate, or its elapsed-time bracket
# ("[00:03, 3.76s/mesh" where the bar has no total)
PROGRESS = re.compile(r"\d+%\||it/s\]|s/it\]|\[\d+:\d\d(:\d\d)?[,<]")


def shown(output: str) -> list[str]:
    """The lines a terminal keeps: progress bars dropped, blank lines too."""
    return [line.rstrip() for line in output.splitlines() if line.strip() and not PROGRESS.search(line)]


def console_commands(text: str) -> list[tuple[str, str, int]]:
    """``(command, expected output, line number)`` for every ``$ `` line of every console block."""
    out = []
    lines = text.splitlines()
    k = 0
    while k < len(lines):
        if lines[k].strip() == "```console":
            k += 1
            while k < len(lines) and lines[k].strip() != "```":
                if lines[k].startswith("$ "):
                    command, start, expected = lines[k][2:], k + 1, []
                    k += 1
                    while k < len(lines) and lines[k].strip() != "```" and not lines[k].startswith("$ "):
                        expected.append(lines[k])
                        k += 1
                    out.append((command, "\n".join(expected), start))
                else:
                    k += 1
        k += 1
    return out


def _timing(key: str) -> bool:
    """Whether a summary's key is a timing: ``seconds``, or a name ending in ``_seconds`` (``element_seconds``)."""
    return key == "seconds" or key.endswith("_seconds")


def _round_off(key: str, value: float) -> float:
    """``value`` as compared: an ``energy_error`` below ``ENERGY_ROUND_OFF`` as 0 (module docstring)."""
    return 0.0 if key == "energy_error" and abs(value) < ENERGY_ROUND_OFF else value


def _drop_seconds(value):
    if isinstance(value, dict):
        return {k: _round_off(k, v) if isinstance(v, float) else _drop_seconds(v) for k, v in value.items()
                if not _timing(k)}
    if isinstance(value, list):
        return [_drop_seconds(v) for v in value]
    return value


def keyed_numbers(output: str) -> list[tuple[str, float]]:
    """The numbers of a command's output, timings left out (see the module docstring), each with the key of its
    line (the first word; empty in JSON output)."""
    text = "\n".join(shown(output))
    if text.startswith("{"):
        text = json.dumps(_drop_seconds(json.loads(text)))
        return [("", float(x)) for x in NUMBER.findall(TIMING.sub("", text))]
    text = "\n".join(line for line in text.splitlines() if not _timing((line.split() or [""])[0]))
    out = []
    for line in TIMING.sub("", text).splitlines():
        key = (line.split() or [""])[0]
        out += [(key, _round_off(key, float(x))) for x in NUMBER.findall(line)]
    return out


def numbers(output: str) -> list[float]:
    """The numbers of a command's output, timings left out (see the module docstring)."""
    return [value for _, value in keyed_numbers(output)]


def close(a: float, b: float, rtol: float = RTOL) -> bool:
    if abs(a) < ATOL and abs(b) < ATOL:
        return True
    return math.isclose(a, b, rel_tol=rtol, abs_tol=0.0)


def test_a_bar_without_a_total_is_progress():
    assert shown("lattice fcc: 1mesh [00:03,  3.76s/mesh, neck size 0.3 a]\nkind  fcc") == ["kind  fcc"]


def test_number_extraction_ignores_timings_and_keeps_the_rest():
    assert numbers("a  1.5e-3\nseconds  0.4\nb  [2 items]\nelement_seconds  2.5") == [1.5e-3, 2.0]
    assert numbers('{"K": 0.25, "seconds": 3.1, "n": [1, 2], "element_seconds": 2.5}') == [0.25, 1.0, 2.0]
    assert numbers("paper      ok        1.8 s  Rojek 2022") == [2022.0]
    assert numbers("fit sweep:  50%|#####     | 20/40 [00:00<00:00, 32.95solve/s]\nslope  1.07") == [1.07]
    assert close(5.4e-17, -2e-16) and close(1.0, 1.0 + 5e-7) and not close(1.0, 1.0 + 2e-6)
    assert numbers("energy_error  5.1e-09\nT_mean  5.1e-09") == [0.0, 5.1e-09]
    assert numbers('{"energy_error": 5.1e-09, "flow": 5.1e-09}') == [0.0, 5.1e-09]
    assert numbers("energy_error  2e-07") == [2e-07]
    assert keyed_numbers("hp_error_ratio_per_order  7.83\nk  1") == [("hp_error_ratio_per_order", 7.83), ("k", 1.0)]


def shown_files(text: str) -> dict:
    """``{name: content}`` of every fenced block that follows a ``<!-- file: NAME -->`` line."""
    out = {}
    for match in re.finditer(r"<!-- file: (\S+) -->\s*\n```\w*\n(.*?)\n```", text, re.S):
        out[match.group(1)] = match.group(2) + "\n"
    return out


def shown_commands(pages, root=ROOT) -> list[tuple[str, str, dict, list[str]]]:
    """``(command, expected output, files, places)`` for every distinct console command of ``pages``: ``files`` are
    the input files its page shows, ``places`` every ``page:line`` that shows it with that output and those of the
    files it names (pages named relative to ``root``)."""
    found = {}
    for page in pages:
        text = page.read_text()
        files = shown_files(text)
        for command, expected, line in console_commands(text):
            named = tuple(sorted((name, content) for name, content in files.items() if name in command))
            key = (command, "\n".join(shown(expected)), named)
            found.setdefault(key, (command, expected, files, []))[3].append(f"{page.relative_to(root)}:{line}")
    return list(found.values())


COMMANDS = shown_commands(PAGES)


def test_pages_have_console_blocks():
    assert len(COMMANDS) >= 8


def test_a_command_shown_twice_runs_once(tmp_path):
    page = "```console\n$ python -m x --a 1\nK  0.5\n```\n"
    other = "<!-- file: s.toml -->\n```toml\nn = 1\n```\n" + page  # shows a file the command does not name
    paths = [tmp_path / name for name in ("a.md", "b.md", "c.md")]
    for path, text in zip(paths, (page, other, page.replace("0.5", "0.6"))):
        path.write_text(text)
    commands = shown_commands(paths, root=tmp_path)
    assert [places for *_, places in commands] == [["a.md:2", "b.md:6"], ["c.md:2"]]  # c.md prints another number


@pytest.mark.parametrize("command, expected, files, places", [
    pytest.param(c, e, f, p, id=f"{p[0]} {c[:60]}", marks=[pytest.mark.slow] if any(s in c for s in SLOW) else [])
    for c, e, f, p in COMMANDS])
def test_console_block(tmp_path, command, expected, files, places):
    argv = shlex.split(command)
    assert argv[0] == "python", f"{places[0]}: only python commands are run"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep),
               MPLBACKEND="Agg")
    for name, content in files.items():
        (tmp_path / name).write_text(content)
    proc = subprocess.run([sys.executable, *argv[1:]], cwd=tmp_path, env=env, stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True, timeout=1800)
    got, want = keyed_numbers(proc.stdout), keyed_numbers(expected)
    message = f"{', '.join(places)}: `{command}` printed\n{proc.stdout}"
    assert len(got) == len(want), message
    bad = [(w, g) for (key, w), (_, g) in zip(want, got) if not close(w, g, KEY_RTOL.get(key, RTOL))]
    assert not bad, f"{message}\n(page, now): {bad}"


# ------------------------------------------------------------------------------------------ numbers in paragraphs
PM = r"(?P<{0}>[\d.]+) ± (?P<{0}_pm>[\d.]+)"  # a figure and its spread, as a paragraph prints it
HOT_WALL = re.compile(
    (r"After 0\.15 s the solid fraction is {hot} next to the hot wall and {top} at the top, the mean neck radius "
     r"\$?a/r\$? {neck_hot} against {neck_top}, and the effective conductivity between the walls has risen to {k_eff} "
     r"W/\(m K\).*?(?P<steps>[\d.]+)·10⁵ steps").format(**{k: PM.format(k) for k in
                                                        ("hot", "top", "neck_hot", "neck_top", "k_eff")})
    .replace(" ", r"\s+"), re.S)  # wrapped anywhere


@pytest.mark.slow
def test_hot_wall_sintering_paragraph(tmp_path):
    """The paragraph on the built-in hot-wall-sintering run (the guide's sintering page): a run of this code lies
    within the spread the paragraph states for each figure (the packing is chaotic: round-off differences between
    machines grow into different trajectories), and takes the step count it states."""
    pages = {page.relative_to(ROOT): HOT_WALL.search(page.read_text()) for page in PAGES}
    pages = {page: shown for page, shown in pages.items() if shown}
    page = pathlib.Path("docs/guide/dem/sintering.md")
    assert page in pages, f"{page}: the hot-wall-sintering paragraph moved or was reworded"
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
    proc = subprocess.run([sys.executable, "-m", "dem", "run", "hot-wall-sintering", "--json"], cwd=tmp_path, env=env,
                          stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, timeout=3600)
    summary = json.loads(proc.stdout)
    profile = summary["profile"]
    ran = {"hot": profile["solid_fraction"][0], "top": profile["solid_fraction"][-1],
           "neck_hot": profile["neck_over_radius"][0], "neck_top": profile["neck_over_radius"][-1],
           "k_eff": summary["effective_conductivity"]}
    for page, shown in pages.items():
        bad = {key: (f"{shown[key]} ± {shown[key + '_pm']}", value) for key, value in ran.items()
               if abs(value - float(shown[key])) > float(shown[key + "_pm"]) * (1 + 1e-9)}
        assert not bad, f"{page}: the hot-wall-sintering paragraph (shown, now): {bad}"
        assert round(summary["steps"] / 1e5, 1) == float(shown["steps"]), page
