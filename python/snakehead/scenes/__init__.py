"""Scenes: head targets and obstacles as data (TOML scene files); the paper's two scenarios ship as scene files
(``spheres.toml``, ``hole.toml``; :func:`paper_scene`)."""
from .scene import APPROACHES, MAX_TARGETS, PAPER_SCENES, Scene, Target, load_scene, paper_scene, scene_from_dict

__all__ = ["Scene", "Target", "load_scene", "scene_from_dict", "paper_scene", "PAPER_SCENES", "APPROACHES", "MAX_TARGETS"]
