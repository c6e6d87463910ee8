"""Finite-element verification of the thermal conductance of sintered necks (Rojek et al. 2022).

``fem_neck.geometry`` is light (numpy only); the meshing and FE solves live in their own modules and import gmsh and
scikit-fem only when used. The names below are loaded from ``fem_neck.geometry`` on first use, so that importing
the package (as ``python -m fem_neck`` does before its CLI takes over Ctrl-C, :mod:`sinterheat.interrupt`) costs
nothing.
"""

__all__ = ["NeckGeometry", "coble_radius", "max_overlap", "neck_geometry", "neck_radius", "overlap_for_neck"]


def __getattr__(name):
    if name in __all__:
        from fem_neck import geometry

        return getattr(geometry, name)
    raise AttributeError(f"module 'fem_neck' has no attribute {name!r}")
