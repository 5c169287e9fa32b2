from pathlib import Path

import pytest

DATA = Path(__file__).resolve().parent / "data"


def head6_robot():
    """The default robot with the 6-DOF head of the paper's Section 2.2 (its shipped robot file)."""
    from snakehead import SnakeRobot, default_robot_file

    return SnakeRobot.from_file(default_robot_file().with_name("snake16_head6.toml"))


@pytest.fixture(scope="session")
def mixed_urdf() -> str:
    """A chain with revolute, continuous, prismatic and fixed joints (tests/data/mixed_chain.urdf)."""
    return str(DATA / "mixed_chain.urdf")
