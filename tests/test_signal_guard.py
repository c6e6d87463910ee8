"""gmsh resets the process's signal handlers when it starts; a mesh must leave them as they were (faulthandler still
prints where a crash happened, a closed pipe still raises BrokenPipeError)."""

import faulthandler
import signal
import subprocess
import sys
import textwrap

import pytest

from fem_neck import shapes, signal_guard

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="the guard reads struct sigaction of glibc")


SA_RESTORER = 0x04000000  # set by glibc on every handler it installs: not part of what the handler does


def _table(saved):
    return {number: (action.handler, action.flags & ~SA_RESTORER) for number, action in saved.items()}


def test_a_mesh_keeps_every_signal_handler():
    was_enabled = faulthandler.is_enabled()
    faulthandler.enable()
    try:
        before = _table(signal_guard.handlers())
        assert before[signal.SIGSEGV][0] is not None  # faulthandler's, not the default
        shapes.semisphere_mesh(0.3)
        assert _table(signal_guard.handlers()) == before
    finally:
        if not was_enabled:
            faulthandler.disable()


@pytest.mark.slow
def test_a_crash_after_a_mesh_still_says_where():
    script = textwrap.dedent("""
        import ctypes, faulthandler
        from fem_neck import shapes
        faulthandler.enable()
        shapes.semisphere_mesh(0.3)
        ctypes.string_at(0)
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert done.returncode == -signal.SIGSEGV
    assert "Fatal Python error: Segmentation fault" in done.stderr and "line 6" in done.stderr, done.stderr
