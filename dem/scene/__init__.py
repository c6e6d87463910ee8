"""Scenes: everything one DEM run needs, read from TOML or built from arrays in Python (:mod:`~dem.scene.parse`);
the moving part of a scene (:mod:`~dem.scene.motion`), its events in time (:mod:`~dem.scene.events`), saved states
to start from (:mod:`~dem.scene.state_file`) and the built-in scenes (``builtin/*.toml``)."""

from dem.scene.parse import (OutputSpec, Scene, SolverSpec, Specimen, builtin_scenes, load_scene,  # noqa: F401
                             make_scene, parse_scene)
