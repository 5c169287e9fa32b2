"""Scenes: head targets and obstacles as data (TOML scene files, read by :func:`load_scene` and written by
:func:`save_scene`); the paper's two scenarios ship as scene files (``spheres.toml``, ``hole.toml``;
:func:`paper_scene`)."""
from .scene import (
                    APPROACHES,
                    MAX_TARGETS,
                    PAPER_SCENES,
                    Scene,
                    Target,
                    load_scene,
                    paper_scene,
                    save_scene,
                    scene_from_dict,
                    scene_to_toml,
                    with_meshes_in,
)

__all__ = ["Scene", "Target", "load_scene", "save_scene", "scene_to_toml", "scene_from_dict", "paper_scene",
           "PAPER_SCENES", "APPROACHES", "MAX_TARGETS", "with_meshes_in"]
