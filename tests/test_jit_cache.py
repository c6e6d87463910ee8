"""The compiled kernels' cache follows every module whose code or constants reach compiled code (numba alone follows
only a function's own file, so a kernel would keep its callees' old code and the constants it was compiled with), in
dem and fem_neck alike, whichever of them a process imports."""

import importlib
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import time

import pytest

from sinterheat import jit_cache

LUDING_MATERIAL = "dem.laws.contact.luding"  # the module that holds the parameter indices of the Luding law
ZOHDI_MATERIAL = "dem.laws.contact.zohdi"


@pytest.fixture
def copy(tmp_path):
    """A copy of the project's packages, to edit: the folder that holds them."""
    for name in jit_cache.PROJECT_PACKAGES:
        shutil.copytree(jit_cache.ROOT / name, tmp_path / name, ignore=shutil.ignore_patterns("__pycache__"))
    return tmp_path


def _in_copy(copy, module):
    """The file of ``module`` (a dotted name) in the copy."""
    return copy / pathlib.Path(importlib.import_module(module).__file__).relative_to(jit_cache.ROOT)


def _edit(path, old, new):
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))


@pytest.mark.slow
def test_the_compiled_modules_are_found_from_their_imports():
    names = {str(p.relative_to(jit_cache.ROOT)) for p in jit_cache.compiled_sources()}
    # the loop, its contact law's kernels, and the module whose parameter indices the kernels compile in
    assert {"dem/engines/verlet/loop.py", "dem/laws/contact/luding.py", "dem/laws/contact/zohdi.py",
            "dem/engines/staggered/kernels.py", "dem/network/gauss_seidel.py"} <= names
    # fem_neck's kernels and the module whose functions the neck kernels compile
    assert {"fem_neck/geometry/neck_kernels.py", "fem_neck/geometry/cut_kernels.py", "fem_neck/geometry/__init__.py",
            "fem_neck/dual.py"} <= names
    assert "dem/cli/scenes.py" not in names and "dem/__init__.py" not in names and "fem_neck/cli/fit.py" not in names


@pytest.mark.slow
def test_swapping_two_parameter_indices_changes_the_key(copy):
    """A change that alters no physics but every compiled kernel that reads the material (the indices are constants
    compiled into them): a cache that missed it would read k2 where k1 is meant."""
    before = jit_cache.digest(copy)
    path = _in_copy(copy, LUDING_MATERIAL)
    text = path.read_text()
    text = re.sub(r"^P_K1 = 0 ", "P_K1 = 1 ", text, count=1, flags=re.M)
    text = re.sub(r"^P_K2 = 1 ", "P_K2 = 0 ", text, count=1, flags=re.M)
    assert text != path.read_text()
    path.write_text(text)
    assert jit_cache.digest(copy) != before


@pytest.mark.slow
def test_an_edit_outside_compiled_code_keeps_the_key(copy):
    before = jit_cache.digest(copy)
    _edit(_in_copy(copy, "dem.cli.scenes"), '"""', '"""An edit. ')
    assert jit_cache.digest(copy) == before
    _edit(_in_copy(copy, ZOHDI_MATERIAL), "Material = ZohdiMaterial", "Material = ZohdiMaterial  # an edit")
    assert jit_cache.digest(copy) != before


@pytest.mark.slow
def test_the_loops_copied_into_the_cache_keep_the_key(copy):
    """dem.engines.compiled writes a copy of the loops for more than one thread into the cache folder, inside the
    package: the key of that folder must not follow them (else every threaded run would compile afresh)."""
    before = jit_cache.remembered_digest(copy)
    copied = copy / "sinterheat" / "__pycache__" / f"numba-{before}" / "threaded" / "contact_forces.py"
    copied.parent.mkdir(parents=True)
    copied.write_text((copy / "dem" / "engines" / "contact_forces.py").read_text())
    assert jit_cache.digest(copy) == jit_cache.remembered_digest(copy) == before


@pytest.mark.slow
def test_an_edit_to_what_fem_necks_kernels_call_changes_the_key(copy):
    """The neck kernels compile functions of fem_neck.geometry (numba's own cache would keep their old code)."""
    before = jit_cache.digest(copy)
    path = copy / "fem_neck" / "geometry" / "__init__.py"
    path.write_text(path.read_text() + "\n# an edit\n")
    assert jit_cache.digest(copy) != before


@pytest.mark.slow
def test_the_remembered_key_follows_an_edit(copy):
    first = jit_cache.remembered_digest(copy)
    assert (copy / "sinterheat" / "__pycache__" / "jit_digest.json").exists()
    assert jit_cache.remembered_digest(copy) == first == jit_cache.digest(copy)
    path = next(p for p in jit_cache.compiled_sources(copy) if p.name == "neighbours.py")
    path.write_text(path.read_text() + "\n# an edit\n")
    os.utime(path, ns=(path.stat().st_atime_ns, path.stat().st_mtime_ns + 10**9))  # a later modification time
    assert jit_cache.remembered_digest(copy) == jit_cache.digest(copy) != first


@pytest.mark.slow
def test_import_points_numba_at_the_digests_folder(tmp_path):
    """Also where numba was imported first (numba's own cache, keyed by each file alone, would otherwise serve
    kernels compiled from older sources of the modules they call), and inside a folder the user chose."""
    folder = f"numba-{jit_cache.digest()}"
    code = ("import os, numba, dem; from numba.core import config; "
            "print(os.environ['NUMBA_CACHE_DIR'], config.CACHE_DIR)")
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    for first in ("import dem, numba", "import numba, dem"):
        out = subprocess.run([sys.executable, "-c", code.replace("import os, numba, dem", f"import os; {first}")],
                             capture_output=True, text=True, env=env, check=True).stdout.split()
        assert [pathlib.Path(o).name for o in out] == [folder, folder], first
    env["NUMBA_CACHE_DIR"] = str(tmp_path)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True).stdout
    assert out.split() == [str(tmp_path / folder)] * 2
    env["NUMBA_CACHE_DIR"] = str(tmp_path / folder)  # a child process of a configured one: the same folder
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True).stdout
    assert out.split() == [str(tmp_path / folder)] * 2


@pytest.mark.slow
def test_fem_neck_alone_points_numba_at_the_digests_folder():
    """A script that uses fem_neck's compiled kernels without dem (an FE study) gets the same cache folder, not numba's
    default one beside each source file, which an edit to a module the kernel calls would leave stale."""
    folder = f"numba-{jit_cache.digest()}"
    code = ("import os, sys; import fem_neck.geometry.neck_kernels; from numba.core import config; "
            "print(os.environ['NUMBA_CACHE_DIR'], config.CACHE_DIR, 'dem' in sys.modules)")
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True).stdout
    cache_env, cache_dir, dem_loaded = out.split()
    assert dem_loaded == "False"
    assert [pathlib.Path(cache_env).name, pathlib.Path(cache_dir).name] == [folder, folder]


@pytest.mark.slow
def test_a_folder_the_user_chose_that_cannot_be_written_is_named_and_left(tmp_path):
    """NUMBA_CACHE_DIR below a file: the run goes on with the kernels cached in the temp folder, a warning names the
    variable, and a child process finds the same folder."""
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    folder = pathlib.Path(tempfile.gettempdir()) / "sinterheat-numba" / f"numba-{jit_cache.digest()}"
    code = ("import os, subprocess, sys, dem; from numba.core import config; print(config.CACHE_DIR); "
            "print(subprocess.run([sys.executable, '-c', 'import dem, os; print(os.environ[\"NUMBA_CACHE_DIR\"])'], "
            "capture_output=True, text=True, check=True).stdout.strip())")
    env = {**os.environ, "NUMBA_CACHE_DIR": str(blocker / "cache")}
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert run.stdout.split() == [str(folder)] * 2
    assert f"NUMBA_CACHE_DIR = '{blocker / 'cache'}': cannot write" in run.stderr and "Traceback" not in run.stderr


def _waits_for(path, process, seconds=600):
    """Wait until ``path`` exists; fail if ``process`` ends first or the time runs out."""
    end = time.monotonic() + seconds
    while not path.exists():
        assert process.poll() is None and time.monotonic() < end, f"no {path.name}"
        time.sleep(0.01)


@pytest.mark.slow
def test_two_processes_saving_signatures_of_one_kernel_at_once_keep_both(tmp_path):
    """As pytest's workers do: process A reads a kernel's index to add its signature and is held before it writes the
    index back; process B saves another signature of the kernel meanwhile. Both must be in the index after (numba's
    own update writes A's index over B's entry, so that every later run compiles B's signature again)."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    ready, saving, go = tmp_path / "ready", tmp_path / "saving", tmp_path / "go"
    kernel = "import os, time, numpy as np; from numba.core import caching; from dem.network import groups\n"
    held = kernel + (  # A: the index read, its write held until go
        "save = caching.IndexDataCacheFile._save_index\n"
        "def held(self, overloads):\n"
        f"    open({str(ready)!r}, 'w').close()\n"
        f"    while not os.path.exists({str(go)!r}): time.sleep(0.01)\n"
        "    save(self, overloads)\n"
        "caching.IndexDataCacheFile._save_index = held\n"
        "groups._root(np.arange(4), 1)")
    other = kernel + (  # B: says when it starts to save
        "save = caching.IndexDataCacheFile.save\n"
        "def saves(self, key, data):\n"
        f"    open({str(saving)!r}, 'w').close()\n"
        "    save(self, key, data)\n"
        "caching.IndexDataCacheFile.save = saves\n"
        "groups._root(np.arange(4, dtype=np.int32), 1)")
    a = subprocess.Popen([sys.executable, "-c", held], env=env)
    b = subprocess.Popen([sys.executable, "-c", other], env=env)
    try:
        _waits_for(ready, a)
        _waits_for(saving, b)
        try:
            b.wait(timeout=1)  # numba's own update finishes at once; a locked one waits for A
        except subprocess.TimeoutExpired:
            pass
        go.touch()
        assert a.wait(timeout=600) == 0 and b.wait(timeout=600) == 0
    finally:
        a.kill()
        b.kill()
    check = ("import numpy as np; from dem.network import groups; groups._root(np.arange(4), 1); "
             "groups._root(np.arange(4, dtype=np.int32), 1); print(sum(groups._root.stats.cache_misses.values()), "
             "sum(groups._root.stats.cache_hits.values()))")
    out = subprocess.run([sys.executable, "-c", check], env=env, capture_output=True, text=True, check=True).stdout
    assert out.split() == ["0", "2"]  # nothing compiled, both signatures loaded
