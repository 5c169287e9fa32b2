"""The folders a robot's description may read: the one place that says which files a description reaches.

A description names other files: xacro includes, YAML files, collision meshes (``package://NAME/...``,
``file://...``, relative or absolute paths). A description that came with a downloaded scene is not trusted, so
every such file must lie inside the robot's folders, checked after symbolic links are resolved:

* the description's own folder, and the robot file's (when the robot came from one);
* the robot file's ``[packages]`` folders (``package://NAME`` and ``$(find NAME)``);
* the folders on ``ROS_PACKAGE_PATH`` (whose sub-folders are packages too).

A path outside them is an :class:`~snakehead.InputError` that names it and the folders, without saying whether it
exists (no file-system oracle).
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping

from .._errors import InputError
from .._validate import input_file

__all__ = ["MAX_DESCRIPTION_BYTES", "RobotFolders"]

#: A description file (URDF, xacro, an included xacro, a YAML file it loads) larger than this is not a snake's.
MAX_DESCRIPTION_BYTES = 16 * 1024 * 1024


@dataclass(frozen=True)
class RobotFolders:
    """The folders a description reads from (``folders``: its own and its robot file's) and its packages
    (NAME -> folder)."""

    folders: tuple[Path, ...] = ()
    packages: Mapping[str, Path] = field(default_factory=dict)

    def package_folder(self, name: str, where: str) -> Path:
        """The folder of package ``name``: the robot file's ``[packages]``, then ROS_PACKAGE_PATH's ``DIR/name``."""
        if name in self.packages:
            return Path(self.packages[name])
        for entry in _ros_package_path():
            if (entry / name).is_dir():
                return entry / name
        raise InputError(f"{where}: package {name!r} is not known; add {name} = \"folder\" to the robot file's "
                         "[packages] table (or put it on ROS_PACKAGE_PATH)")

    def roots(self) -> list[Path]:
        """Every folder a description may read inside, resolved."""
        return [Path(p).resolve() for p in (*self.folders, *self.packages.values(), *_ros_package_path())]

    def inside(self, path: str | os.PathLike[str], what: str, max_bytes: int) -> Path:
        """``path`` resolved, if it is a regular file of at most ``max_bytes`` inside the robot's folders;
        otherwise an InputError naming ``what`` and the path."""
        text = os.fspath(path)
        if "\0" in text:
            raise InputError(f"{what} {text!r}: the path holds a NUL character")
        resolved = Path(text).resolve()
        roots = self.roots()
        if not any(resolved.is_relative_to(root) for root in roots):
            shown = ", ".join(repr(os.fspath(r)) for r in roots) or "none: the description was given as text"
            raise InputError(f"{what} {text!r} is outside the robot's folders ({shown}); a description reads only "
                             "files in its own folder, its robot file's and its [packages]")
        return input_file(resolved, what, max_bytes)


def _ros_package_path() -> list[Path]:
    return [Path(e) for e in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if e]
