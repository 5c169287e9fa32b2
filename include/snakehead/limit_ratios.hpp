// How samples of a timed motion use their limits (motion/timing.py's _ratios, which the retiming's probes between
// gridpoints and check_limits ask for): per sample, the largest |value| / limit of the joint velocities,
// accelerations and torques, the friction used, and the ZMP's signed distance inside its support polygon
// (Eqs. 39-40 with p_z = 0). The same operations in the same order as the numpy they replace: the same numbers.
#pragma once

#include <vector>

namespace snakehead {

struct LimitRatios {
  std::vector<double> velocity, acceleration, torque, friction, zmp_margin;  // (N,) each
};

// qd, qdd, tau (N x n), Pdot, Ldot, com (N x 3; dP/dt and dL/dt about the world origin), normal (N x E x 2: each
// sample's polygon edges as inward unit normals, padded by repeating one), offset (N x E: inside where
// normal . p >= offset), velocity, acceleration, torque (n limits, > 0), Mg (the body's weight across the ground,
// N), Mg_x, Mg_y (its part along the ground: zero on flat ground; on a slope the contact force's tangential part is
// dP_xy/dt - M g_xy), friction (mu): all row-major. On a slope `com` is the point on the ground below the CoM along
// gravity (its z kept), which turns Eqs. 39-40 into the slope's ZMP. Where M g + dP_z/dt <= 0 (the ground would have to pull) the ZMP's margin is -inf and the friction
// used +inf. Throws InputError on sizes below 1 (N may be 0).
LimitRatios limit_ratios(long N, long n, long E, const double* qd, const double* qdd, const double* tau,
                         const double* Pdot, const double* Ldot, const double* com, const double* normal,
                         const double* offset, const double* velocity, const double* acceleration,
                         const double* torque, double Mg, double friction, double Mg_x = 0.0,
                         double Mg_y = 0.0);

}  // namespace snakehead
