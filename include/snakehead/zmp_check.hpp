// The dynamic-stability (ZMP) check of a sampled motion on a PathChecker's chain, origin and shapes (zmp_check below).
#pragma once

#include <limits>
#include <vector>

#include "snakehead/dynamics.hpp"
#include "snakehead/path_check.hpp"

namespace snakehead {

// The dynamic-stability check of a sampled motion (Section 3.1, Eqs. 25-40) with contact "ground" or "footprint",
// sample for sample what snakehead.dynamics.stability.dynamic_stability computes in Python: the momenta P, L and
// the CoM (Eqs. 23, 25-31), their time derivatives by np.gradient's second-order differences (Eqs. 33-34), the ZMP
// on the ground (Eqs. 36-40; NaN where M g + dP_z/dt <= 0) and its signed distance to the convex hull of the
// contact points touching the ground (tolerance) of the first sample of each run of samples with one contact
// configuration (runs also restart every `chunk` samples, as the Python's chunks do); with the lowest z of
// `clearance_shapes` per sample.
struct ZmpCheckSpec {
  std::vector<long> contact_shapes;   // robot shapes whose lowest candidate points may touch
  long points_per_shape = 4;          // the lowest candidates of each shape (ShapeSet lowest_points)
  std::vector<long> clearance_shapes; // robot shapes whose lowest z (min over them) is reported per sample
  bool ground_key = true;             // contact "ground": the runs' key is the joints before the last touching link
  std::vector<int> key_joints;        // otherwise: these joints (the base's)
  std::vector<int> shaped_links;      // links with shapes (ground key: which touch)
  double tolerance = 1e-3;
  long chunk = 4096;
  // g (m/s^2) in the ground frame (the caller's: BasePlacement.gravity): (0, 0, -GRAVITY) on flat ground; on a
  // slope it leans, and the ZMP on the ground plane takes the lean in (g_x, g_y != 0; g_z < 0 always)
  Eigen::Vector3d gravity = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
};

struct ZmpCheck {
  std::vector<double> zmp, margin, linear, angular, com, clearance;  // T x 2, T, T x 3 (three), T
  long resumed = 0;  // samples taken over from a ZmpPrefix
};

// What zmp_check computed sample by sample (momenta, CoM, clearance, the contact runs and their polygons) over the
// first samples of a motion, kept so that a later check of a motion that begins with the same samples (the lift
// from the bending state is the same for every target from a base of one shape) takes it over instead of computing
// it again. zmp_check takes it over only when the checker's model and shapes, the spec and the prefix's q and qd are
// those it was made with, bit for bit (else it computes everything). At the same origin the result is then the same
// as without it, to the bit (the per-sample values depend on their own sample only, the runs on the samples before;
// the time derivatives and the ZMP are computed over the whole motion afterwards). At an origin that differs only by
// where the base lies on the ground (the origins' z rows the same to the bit: a turn about z and a shift in x, y)
// the heights, clearances and contact runs are the same to the bit (every world frame's z row is), and the momenta,
// CoM and polygons are moved with the placement (P' = R P, c' = R c + t, L' = R L + t x P'): the same as computed
// there up to round-off (~1e-15 m; the ZMP's margins to 1e-12 m).
struct ZmpPrefix {
  const ChainModel* model = nullptr;
  const ShapeSet* shapes = nullptr;
  Eigen::Matrix4d origin = Eigen::Matrix4d::Zero();
  ZmpCheckSpec spec;
  std::vector<double> q, qd;                           // the samples it was made from (m x n each)
  std::vector<double> linear, angular, com, clearance;  // m x 3 (three), m
  std::vector<long> run;                                // m: each sample's run
  std::vector<double> vertices;                         // the runs' hull vertices (flat x, y)
  std::vector<long> start;                              // run r's vertices: start[r] .. start[r + 1] - 1
  std::vector<double> last_key;                         // the contact key of the last sample's run
  long size() const { return static_cast<long>(run.size()); }
};

// resume: a prefix to take over (when it matches, see ZmpPrefix); keep > 0: the first min(keep, T) samples' part
// is written to *kept.
ZmpCheck zmp_check(const PathChecker& checker, const RigidBodyChain& chain, const ZmpCheckSpec& spec,
                   const double* t, const double* q, const double* qd, long T, const ZmpPrefix* resume = nullptr,
                   long keep = 0, ZmpPrefix* kept = nullptr);

// d/dt of x (T x m) sampled at t (T), as numpy.gradient(x, t, axis=0, edge_order=2 if T > 2 else 1).
void time_derivative(const double* t, const double* x, long T, long m, double* out);

}  // namespace snakehead
