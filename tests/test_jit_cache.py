"""The compiled kernels' cache follows every compiled module's source (numba alone follows only a function's own
file, so a kernel would keep its callees' old code)."""

import os
import subprocess
import sys

from dem import jit_cache


def test_cache_folder_is_named_by_every_compiled_source(tmp_path, monkeypatch):
    before = jit_cache.digest()
    copy = tmp_path / "dem"
    (copy / "laws").mkdir(parents=True)
    for name in jit_cache.SOURCES:
        (copy / name).write_bytes((jit_cache.PACKAGE / name).read_bytes())
    monkeypatch.setattr(jit_cache, "PACKAGE", copy)
    assert jit_cache.digest() == before
    (copy / "laws" / "luding_kernels.py").write_text((copy / "laws" / "luding_kernels.py").read_text() + "\n# edit\n")
    assert jit_cache.digest() != before


def test_import_sets_the_cache_folder_unless_the_user_did():
    code = "import os, dem; print(os.environ['NUMBA_CACHE_DIR'])"
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True).stdout
    assert f"numba-{jit_cache.digest()}" in out or jit_cache.digest() in out
    env["NUMBA_CACHE_DIR"] = "/tmp/mine"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True).stdout
    assert out.strip() == "/tmp/mine"
