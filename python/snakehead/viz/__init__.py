"""Figures and animations (matplotlib): the body, the backbone, the workspace maps, the dynamics."""
