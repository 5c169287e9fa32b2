"""The ``snakehead`` command (also ``python3 -m snakehead``)."""
from __future__ import annotations

import argparse
import sys

import numpy as np


def _info(args: argparse.Namespace) -> int:
    from .robot import SnakeRobot

    robot = SnakeRobot.default()
    print(f"robot: {robot.urdf}")
    print(f"joints: {robot.n_joints}, mass {robot.total_mass:.3f} kg, frames: {', '.join(robot.link_names)}")
    q = np.zeros(robot.n_joints)
    np.set_printoptions(precision=4, suppress=True)
    print("head_tip at q = 0 (world):")
    print(robot.head_pose(q))
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="snakehead", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("info", help="describe the default robot and print its head pose at q = 0")
    p.set_defaults(func=_info)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except ValueError as exc:
        print(f"snakehead: error: {exc}", file=sys.stderr)
        return 2
