"""Finite-element verification of the thermal conductance of sintered necks (Rojek et al. 2022).

``fem_neck.geometry`` is light (numpy only); the meshing and FE solves live in their own modules and import gmsh and
scikit-fem only when used. The names below are loaded from ``fem_neck.geometry`` on first use, so that importing
the package (as ``python -m fem_neck`` does before its CLI takes over Ctrl-C, :mod:`sinterheat.interrupt`) costs
little: it only points numba's on-disk cache at the folder of the compiled sources' digest
(:mod:`sinterheat.jit_cache`) before any module of the package compiles a kernel, Ctrl-C held to one line from its
first statement under ``python -m`` (:func:`sinterheat.startup.hold`).
"""

import sys

if sys.argv[:1] == ["-m"]:  # imported by `python -m fem_neck`, before its __main__: Ctrl-C held from here on
    from sinterheat.startup import hold

    hold("python -m fem_neck")

from sinterheat import jit_cache  # noqa: E402

jit_cache.configure()  # before numba is imported: compiled kernels cached per version of their source

__all__ = ["NeckGeometry", "coble_radius", "max_overlap", "neck_geometry", "neck_radius", "overlap_for_neck"]


def __getattr__(name):
    if name in __all__:
        from fem_neck import geometry

        return getattr(geometry, name)
    raise AttributeError(f"module 'fem_neck' has no attribute {name!r}")
