"""The control process of Section 3.3 from any lying state, closed in MuJoCo on the robot's own senses: the
supervisor (:mod:`.loop`) and one run of it (:mod:`.episode`), the checks of where the base must go
(:mod:`.goal_checks`), the locomotion along routes around obstacles (:mod:`.route_follower`), what a run records and
reports (:mod:`.loop_run`), the body's pose estimated from joint angles and one IMU (:mod:`.estimate`) or fixed from
outside (:mod:`.pose_fix`), the head's final approach on its camera (:mod:`.servo`), and gaits run in the simulation
(:mod:`.gait_runner`)."""
from .estimate import BodyPose, BodyPoseEstimator, pose_error
from .gait_runner import GaitRun, GaitSimulator
from .loop import ClosedLoop, LoopRun

__all__ = ["ClosedLoop", "LoopRun", "GaitSimulator", "GaitRun", "BodyPose", "BodyPoseEstimator", "pose_error"]
