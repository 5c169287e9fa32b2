"""The ground as data: the surfaces a robot may lie on (:mod:`.surfaces`: flat ground, planes, heightfields,
triangle meshes, staircases, each queried in the C++ core for heights, normals and signed distances), the files
they are read from (:mod:`.terrain_files`: ``.npy``, 16-bit PNG, OBJ/STL/PLY) and the terrains the benchmark
generates (:mod:`.generated`: slopes, steps, undulations, egg-crates). Flat ground (z = 0) is the default wherever
a terrain is held."""
from .generated import egg_crate, slope, staircase, step, undulating
from .surfaces import (
    TERRAIN_TYPES,
    FlatGround,
    HeightfieldTerrain,
    MeshTerrain,
    PlaneTerrain,
    StepsTerrain,
    Terrain,
    TerrainQueries,
)

__all__ = ["FlatGround", "PlaneTerrain", "HeightfieldTerrain", "MeshTerrain", "StepsTerrain", "Terrain",
           "TerrainQueries", "TERRAIN_TYPES", "slope", "step", "staircase", "undulating", "egg_crate"]
