"""Gaits: joint-angle generators for any snake of alternating yaw and pitch joints (the serpenoid family).

Every joint follows a travelling sine wave of its kind (yaw or pitch), written on the body's arc length s (m from
the root frame along the straight body, L the body's length) so that one set of parameters fits any robot:

    q_j(t) = sign_j [offset_k + e(t) A_k(s_j) sin(2 pi (phi(t) - w_k s_j / L) + phase_k)]       k = kind of joint j

* A_k: the wave's amplitude (rad); A_k(s) = A_k (1 - taper_k + taper_k (2 s / L - 1)): taper 0 is a uniform
  amplitude, 1 one that runs linearly from -A at the tail through 0 mid-body to +A at the head (the two halves
  then move in opposite directions: how the turning gait turns);
* w_k: waves per body length (> 0: the wave runs towards the head); phase_k (rad); offset_k (rad);
* phi(t) = frequency * (t - ramp), held at 0 while the amplitudes ramp up (e rises from 0 to 1 over ``ramp_s``)
  and at ``cycles`` while they ramp down, so that a run of N cycles starts and ends with the body straight and
  the wave at the same phase;
* sign_j = +1 where the joint turns about the root frame's +z (yaw) or +y (pitch) axis, -1 for -z or -y
  (``SnakeRobot.joint_signs``): a positive yaw angle bends the body to its left, a positive pitch angle down.

The gaits (:data:`GAITS`, :func:`make_gait`), each with its commanded direction (``direction`` +1 or -1):

* :func:`rolling`: both waves without spatial frequency, a quarter cycle apart: the body bends into an arc whose
  plane turns about the body's axis, so the body rolls over its side. direction +1 rolls to the body's left
  (+y of its frame). The arc starts and ends concave up, so whole cycles leave the body upright.
* :func:`sidewinding`: both waves with the same spatial frequency (1.5 waves per body by default), a quarter
  cycle apart: the yaw wave bends the body in the ground plane and the pitch wave lifts it where it is not in
  contact; the contact patches stay put on the ground and the body moves sideways. direction +1: to the left.
* :func:`turning` (in place): sidewinding with the pitch wave tapered through zero mid-body: the head half
  sidewinds one way and the tail half the other, so the body turns about its middle. direction +1:
  counter-clockwise seen from above (the head to the left).
* :func:`linear_progression`: a pitch wave alone (a vertical travelling wave, the "linear progression" of modular
  snake robots): the links in contact stay put while the lifted crests travel along the body, so the body creeps
  along its own axis, the one way the other gaits cannot move it on an isotropic friction ground. direction +1:
  towards the head. Its sweep is the straight body's own outline, lengthened along the axis.
* :func:`lateral_undulation`: a yaw wave alone, running from the head to the tail. It propels a snake only on a
  ground that resists sideways slip more than forward slip; on snakehead's isotropic friction ground it barely
  moves (bench/RESULTS.md).

Why the signs: take the lateral displacement of the yaw wave, y = -a sin(psi) for curvature A sin(psi), and the
height of the pitch wave, z = +b sin(psi + delta) (a positive pitch angle bends the body down). The body rests on
the ground where z is least, psi + delta = -pi/2, and the ground holds those patches still, so the body's axis
moves at -dy/dt there = -2 pi f a sin(delta): sidewinding with delta = +pi/2 goes to the right (-y). In rolling
(no spatial wave) the curvature (A sin psi, -A sin(psi + delta)) in the body's (y, z) plane turns about the body's
axis at +2 pi f for delta = +pi/2; the arc stays lying on the ground, so the body itself turns about its axis at
-2 pi f and rolls (as a cylinder rolling on the ground) towards +y.

:meth:`Gait.trajectory` samples a run at the 2 ms control period; :mod:`snakehead.closed_loop.gait_runner` runs it
in MuJoCo.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import numpy.typing as npt

from .._errors import InputError, InputTypeError
from .._validate import duration, finite_array, finite_float, integer, positive, sample_count
from ..model.robot import PITCH, YAW, SnakeRobot, as_robot
from ..trajectory.interpolation import CONTROL_PERIOD

__all__ = ["MIN_JOINTS_PER_WAVE", "Wave", "Gait", "virtual_chassis", "rolling", "sidewinding", "turning",
           "linear_progression", "lateral_undulation", "GAITS", "make_gait"]

#: The fewest joints of a kind per wave (fewer alias the wave: it no longer looks like a wave on the body).
MIN_JOINTS_PER_WAVE = 3.0


def _non_negative(value: Any, name: str) -> float:
    v = finite_float(value, name)
    if v < 0:
        raise InputError(f"{name} must be >= 0, got {value!r}")
    return v


def _direction(value: Any) -> int:
    if isinstance(value, bool) or value not in (1, -1):
        raise InputError(f"direction must be +1 or -1, got {value!r}")
    return int(value)


@dataclass(frozen=True)
class Wave:
    """One travelling wave of joint angles (see the module): amplitude (rad, >= 0), waves per body length
    (> 0 runs towards the head), phase and offset (rad), taper (0..1)."""

    amplitude: float = 0.0
    waves: float = 0.0
    phase: float = 0.0
    offset: float = 0.0
    taper: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "amplitude", _non_negative(self.amplitude, "amplitude"))
        for key in ("waves", "phase", "offset"):
            object.__setattr__(self, key, finite_float(getattr(self, key), key))
        taper = finite_float(self.taper, "taper")
        if not 0.0 <= taper <= 1.0:
            raise InputError(f"taper must be within [0, 1], got {self.taper!r}")
        object.__setattr__(self, "taper", taper)

    def amplitudes(self, s: np.ndarray) -> np.ndarray:
        """Amplitude (rad) at body fractions s = arc length / body length, (k,)."""
        return self.amplitude * (1.0 - self.taper + self.taper * (2.0 * s - 1.0))


@dataclass(frozen=True)
class Gait:
    """A gait: a yaw wave, a pitch wave, a frequency (Hz), the ramp (s) that starts and ends it, and what it is
    commanded to do: ``motion`` "translate" (``direction`` +1 to the body's left, -1 to its right; "forward" for
    lateral undulation) or "turn" (+1 counter-clockwise from above). Build one with the gait functions or
    :func:`make_gait`."""

    name: str
    yaw: Wave
    pitch: Wave
    frequency: float
    direction: int
    motion: str
    ramp_s: float = 1.0
    parameters: dict = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "frequency", positive(self.frequency, "frequency"))
        object.__setattr__(self, "ramp_s", _non_negative(self.ramp_s, "ramp_s"))
        object.__setattr__(self, "direction", _direction(self.direction))
        if self.motion not in ("translate", "turn", "forward"):
            raise InputError(f"motion must be 'translate', 'turn' or 'forward', got {self.motion!r}")
        if not isinstance(self.yaw, Wave) or not isinstance(self.pitch, Wave):
            raise InputTypeError("yaw and pitch must be Wave objects")

    @property
    def period_s(self) -> float:
        return 1.0 / self.frequency

    def duration(self, cycles: float) -> float:
        """Length (s) of a run of ``cycles`` cycles with its two ramps."""
        return positive(cycles, "cycles") / self.frequency + 2.0 * self.ramp_s

    def check(self, robot: SnakeRobot) -> None:
        """ValueError if the robot cannot run the gait: joints beyond their limits, or too few joints of a kind
        per wave (fewer than MIN_JOINTS_PER_WAVE)."""
        robot = as_robot(robot)
        s = robot.joint_arc_lengths / robot.body_length
        for kind, wave in ((YAW, self.yaw), (PITCH, self.pitch)):
            mine = np.array([k == kind for k in robot.joint_kinds])
            if wave.amplitude == 0.0 and wave.offset == 0.0:
                continue
            if not mine.any():
                raise InputError(f"the {self.name} gait needs {kind} joints; this robot has none")
            if wave.amplitude > 0 and abs(wave.waves) > 0:
                per_wave = mine.sum() / abs(wave.waves)
                if per_wave < MIN_JOINTS_PER_WAVE:
                    raise InputError(f"{self.name}: {abs(wave.waves):g} waves per body leave {per_wave:.1f} {kind} "
                                     f"joints per wave on this robot ({mine.sum()} {kind} joints); at least "
                                     f"{MIN_JOINTS_PER_WAVE:g} are needed: use fewer waves")
            reach = np.abs(wave.offset) + np.abs(wave.amplitudes(s[mine]))
            lim = np.minimum(-robot.lower[mine], robot.upper[mine])
            if np.any(reach > lim + 1e-12):
                j = int(np.flatnonzero(mine)[np.argmax(reach - lim)])
                raise InputError(f"{self.name}: joint {robot.joint_names[j]!r} would reach "
                                 f"{math.degrees(reach.max()):.1f} deg, beyond its limit of "
                                 f"{math.degrees(lim.min()):.1f} deg: lower the amplitude")

    def joint_angles(self, robot: SnakeRobot, t: npt.ArrayLike, cycles: float) -> np.ndarray:
        """Joint angles (T, n) rad at times t (T,) s from the start of a run of ``cycles`` cycles."""
        robot = as_robot(robot)
        t = np.atleast_1d(finite_array(t, "t"))
        if t.ndim != 1:
            raise InputError(f"t must be a time or a 1-D array of times, got shape {t.shape}")
        self.check(robot)
        cycles = positive(cycles, "cycles")
        running = cycles / self.frequency
        tr = t - self.ramp_s
        phase = self.frequency * np.clip(tr, 0.0, running)  # in cycles
        if self.ramp_s > 0:
            rise = np.clip(t / self.ramp_s, 0.0, 1.0)
            fall = np.clip((self.duration(cycles) - t) / self.ramp_s, 0.0, 1.0)
            envelope = 0.5 - 0.5 * np.cos(np.pi * np.minimum(rise, fall))
        else:
            envelope = np.ones_like(t)
        s = robot.joint_arc_lengths / robot.body_length
        q = np.zeros((t.size, robot.n_joints))
        for kind, wave in ((YAW, self.yaw), (PITCH, self.pitch)):
            mine = np.array([k == kind for k in robot.joint_kinds])
            psi = 2.0 * np.pi * (phase[:, None] - wave.waves * s[None, mine]) + wave.phase
            q[:, mine] = wave.offset + envelope[:, None] * wave.amplitudes(s[mine])[None, :] * np.sin(psi)
        return q * robot.joint_signs[None, :]

    def shape_height(self, robot: SnakeRobot, samples: int = 40) -> float:
        """How high (m) the gait's shape reaches over one cycle at full amplitude: the largest extent of the links'
        collision shapes across the plane of the body (along the virtual chassis' z-axis). Resting on that plane, no
        link rises higher than this; sidewinding and turning lift links by design, to about this height."""
        robot = as_robot(robot)
        samples = integer(samples, "samples", least=1, most=10_000)
        t = self.ramp_s + np.linspace(0.0, self.period_s, samples, endpoint=False)
        F = robot.frames_many(self.joint_angles(robot, t, 1.0))
        corners = robot.hull_points(F)  # (T, k, M, 3)
        centres = robot.link_centres(F)  # (T, k, 3)
        height = 0.0
        for c, pts in zip(centres, corners):
            normal = virtual_chassis(c)[:3, 2]
            h = pts.reshape(-1, 3) @ normal
            height = max(height, float(h.max() - h.min()))
        return height

    def trajectory(self, robot: SnakeRobot, cycles: float, dt: float = CONTROL_PERIOD) -> tuple[np.ndarray, np.ndarray]:
        """A run of ``cycles`` cycles sampled every ``dt`` s: t (T,) s from 0, q (T, n) rad; straight at both ends
        (unless the waves have offsets)."""
        dt = duration(dt, "dt", maximum=1.0)
        total = duration(self.duration(cycles), f"a run of {cycles!r} cycles of the {self.name} gait")
        sample_count(total, dt, f"a run of {cycles!r} cycles of the {self.name} gait")
        t = np.arange(0.0, total + 0.5 * dt, dt)
        t[-1] = min(t[-1], total)
        return t, self.joint_angles(robot, t, cycles)


def virtual_chassis(points: np.ndarray, previous: np.ndarray | None = None, forward: npt.ArrayLike | None = None
                    ) -> np.ndarray:
    """The virtual chassis (4, 4) of body points (k, 3) given in some frame (world): origin at their centroid,
    axes the principal axes of the points (x the longest), z turned up (+z of the frame) and x kept close to
    ``previous``'s x-axis (a 3x3 or 4x4 frame) or, without one, close to ``forward`` (e.g. tail -> head).
    The body's own frame while a gait changes its shape (after Rollinson and Choset, IROS 2011)."""
    points = np.asarray(points, float)
    centre = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - centre, full_matrices=True)
    x, z = vt[0], vt[2]
    if z[2] < 0:
        z = -z
    ref = None if previous is None else np.asarray(previous)[:3, 0]
    if ref is None and forward is not None:
        ref = np.asarray(forward, float)
    if ref is not None and x @ ref < 0:
        x = -x
    y = np.cross(z, x)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, y, z, centre
    return T


def _quarter(direction: int) -> float:
    return direction * math.pi / 2


def rolling(direction: int = 1, *, amplitude: float = 0.3, frequency: float = 0.5, ramp_s: float = 1.0) -> Gait:
    """Roll over the body's side; direction +1 to its left. amplitude (rad) of every joint; frequency in Hz (one
    cycle: one turn of the body about its axis)."""
    direction = _direction(direction)
    delta = _quarter(direction)
    start = -delta  # the arc lies on the ground (yaw joints bent, pitch joints straight) at the start and end
    return Gait("rolling", Wave(amplitude, 0.0, start), Wave(amplitude, 0.0, start + delta), frequency, direction,
                "translate", ramp_s, dict(amplitude=amplitude, frequency=frequency, ramp_s=ramp_s))


def sidewinding(direction: int = 1, *, yaw_amplitude: float = 0.6, pitch_amplitude: float = 0.15,
                waves: float = 1.5, frequency: float = 0.5, ramp_s: float = 1.0) -> Gait:
    """Move sideways; direction +1 to the body's left. Amplitudes in rad, waves per body length, frequency Hz."""
    direction = _direction(direction)
    return Gait("sidewinding", Wave(yaw_amplitude, waves), Wave(pitch_amplitude, waves, -_quarter(direction)),
                frequency, direction, "translate", ramp_s,
                dict(yaw_amplitude=yaw_amplitude, pitch_amplitude=pitch_amplitude, waves=waves, frequency=frequency,
                     ramp_s=ramp_s))


def turning(direction: int = 1, *, yaw_amplitude: float = 0.6, pitch_amplitude: float = 0.2, waves: float = 1.5,
            frequency: float = 0.5, ramp_s: float = 1.0) -> Gait:
    """Turn in place about the body's middle; direction +1 counter-clockwise seen from above."""
    direction = _direction(direction)
    return Gait("turning", Wave(yaw_amplitude, waves), Wave(pitch_amplitude, waves, -_quarter(direction), taper=1.0),
                frequency, direction, "turn", ramp_s,
                dict(yaw_amplitude=yaw_amplitude, pitch_amplitude=pitch_amplitude, waves=waves, frequency=frequency,
                     ramp_s=ramp_s))


def linear_progression(direction: int = 1, *, amplitude: float = 0.5, waves: float = 1.0, frequency: float = 0.5,
                       ramp_s: float = 1.0) -> Gait:
    """Creep along the body's axis; direction +1 towards the head (a pitch wave running towards the head;
    bench/RESULTS.md measures how far). amplitude (rad) of the pitch joints, waves per body length, frequency Hz."""
    direction = _direction(direction)
    return Gait("linear_progression", Wave(0.0), Wave(amplitude, direction * waves), frequency, direction, "forward",
                ramp_s, dict(amplitude=amplitude, waves=waves, frequency=frequency, ramp_s=ramp_s))


def lateral_undulation(direction: int = 1, *, amplitude: float = 0.6, waves: float = 1.0, frequency: float = 0.5,
                       ramp_s: float = 1.0) -> Gait:
    """A yaw wave running from the head to the tail (direction +1: meant to go forward, towards the head). Needs a
    ground with anisotropic friction to get anywhere."""
    direction = _direction(direction)
    return Gait("lateral_undulation", Wave(amplitude, -direction * waves), Wave(0.0), frequency, direction,
                "forward", ramp_s, dict(amplitude=amplitude, waves=waves, frequency=frequency, ramp_s=ramp_s))


#: The gaits by name.
GAITS: dict[str, Callable[..., Gait]] = {"rolling": rolling, "sidewinding": sidewinding, "turning": turning,
                                        "linear_progression": linear_progression,
                                        "lateral_undulation": lateral_undulation}


def make_gait(name: str, direction: int = 1, **parameters: Any) -> Gait:
    """The gait called ``name`` (one of :data:`GAITS`) with its commanded ``direction`` and parameters."""
    if not isinstance(name, str) or name not in GAITS:
        raise InputError(f"unknown gait {name!r}; the gaits are {', '.join(GAITS)}")
    try:
        return GAITS[name](direction, **parameters)
    except TypeError as exc:
        raise InputTypeError(f"{name}: {exc}") from None
