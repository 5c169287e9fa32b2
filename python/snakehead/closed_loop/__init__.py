"""The control process of Section 3.3 from any lying state, closed in MuJoCo on the robot's own senses: the
supervisor (:mod:`.loop`), the body's pose estimated from joint angles and one IMU (:mod:`.estimate`), the head's
final approach on its camera (:mod:`.servo`), and gaits run in the simulation (:mod:`.gait_runner`)."""
from .estimate import BodyPose, BodyPoseEstimator, pose_error
from .gait_runner import GaitRun, GaitSimulator
from .loop import ClosedLoop, LoopRun

__all__ = ["ClosedLoop", "LoopRun", "GaitSimulator", "GaitRun", "BodyPose", "BodyPoseEstimator", "pose_error"]
