"""Finite-element verification of the thermal conductance of sintered necks (Rojek et al. 2022).

``fem_neck.geometry`` is light (numpy only); the meshing and FE solves live in their own modules and import gmsh and
scikit-fem only when used.
"""

from fem_neck.geometry import (
    NeckGeometry,
    coble_radius,
    max_overlap,
    neck_geometry,
    neck_radius,
    overlap_for_neck,
)

__all__ = ["NeckGeometry", "coble_radius", "max_overlap", "neck_geometry", "neck_radius", "overlap_for_neck"]
