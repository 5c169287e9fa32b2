#include "snakehead/box_collision.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "snakehead/model.hpp"

namespace snakehead {

double box_box_sat(const OrientedBox& a, const OrientedBox& b, double stop_above) {
  const Eigen::Vector3d& ha = a.half_extents;
  const Eigen::Vector3d& hb = b.half_extents;
  const Eigen::Matrix3d C = b.rotation.transpose() * a.rotation;  // column i: a's axis i in b's frame
  const Eigen::Vector3d t = b.rotation.transpose() * (a.centre - b.centre);  // a's centre in b's frame
  const Eigen::Matrix3d absC = C.cwiseAbs();
  double best = -std::numeric_limits<double>::infinity();
  for (int j = 0; j < 3; ++j)  // b's face normals
    best = std::max(best, std::abs(t(j)) - hb(j) - absC.row(j).dot(ha));
  for (int i = 0; i < 3; ++i)  // a's face normals
    best = std::max(best, std::abs(C.col(i).dot(t)) - ha(i) - absC.col(i).dot(hb));
  if (best > stop_above) return best;
  for (int i = 0; i < 3; ++i) {  // a's edge i x b's edge j
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      // The axis b_j x a_i is (0, -C(j2, i), C(j1, i)) in b's frame (indices cyclic from j): its length, the
      // sine of the edges' angle, is taken from the same two entries the projections use, not as
      // sqrt(1 - C(j, i)^2), whose rounding (~1e-8 for parallel edges) would be divided into noise and could
      // report ~0 m for boxes that overlap deeply. Parallel edges give no axis (the face normals cover them).
      const double length = std::sqrt(C(j1, i) * C(j1, i) + C(j2, i) * C(j2, i));
      if (!(length > 1e-9)) continue;
      const double proj = std::abs(t(j2) * C(j1, i) - t(j1) * C(j2, i));
      const double ra = ha(i1) * absC(j, i2) + ha(i2) * absC(j, i1);
      const double rb = hb(j1) * absC(j2, i) + hb(j2) * absC(j1, i);
      best = std::max(best, (proj - ra - rb) / length);
    }
    if (best > stop_above) return best;
  }
  return best;
}

namespace {

// Checks box_pair_gaps' input (see the header) and reads box b of sample t.
class BoxBatch {
 public:
  BoxBatch(const double* centres, const double* rotations, const double* half_extents, const long* pairs, long T,
           long k, long P)
      : centres_(centres), rotations_(rotations), half_extents_(half_extents), k_(k) {
    if (T < 0 || k < 0 || P < 0) throw InputError("box_pair_gaps: negative size");
    for (long p = 0; p < P; ++p)
      for (int e = 0; e < 2; ++e)
        if (pairs[2 * p + e] < 0 || pairs[2 * p + e] >= k)
          throw InputError("box_pair_gaps: pair " + std::to_string(p) + " names box " +
                           std::to_string(pairs[2 * p + e]) + "; there are " + std::to_string(k) + " boxes");
    for (long i = 0; i < 3 * k; ++i)
      if (!std::isfinite(half_extents[i]) || half_extents[i] < 0.0)
        throw InputError("box_pair_gaps: half extents must be finite and >= 0");
    for (long i = 0; i < 3 * T * k; ++i)
      if (!std::isfinite(centres[i])) throw InputError("box_pair_gaps: centres must be finite");
    for (long i = 0; i < 9 * T * k; ++i)
      if (!std::isfinite(rotations[i])) throw InputError("box_pair_gaps: rotations must be finite");
  }

  OrientedBox operator()(long t, long b) const {
    using RowMajor3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
    const long tb = t * k_ + b;
    return OrientedBox{Eigen::Map<const Eigen::Vector3d>(centres_ + 3 * tb),
                       Eigen::Map<const RowMajor3>(rotations_ + 9 * tb),
                       Eigen::Map<const Eigen::Vector3d>(half_extents_ + 3 * b)};
  }

 private:
  const double* centres_;
  const double* rotations_;
  const double* half_extents_;
  long k_;
};

}  // namespace

void box_pair_gaps(const double* centres, const double* rotations, const double* half_extents, const long* pairs,
                   long T, long k, long P, double* gaps) {
  const BoxBatch box(centres, rotations, half_extents, pairs, T, k, P);
  for (long t = 0; t < T; ++t)
    for (long p = 0; p < P; ++p) gaps[t * P + p] = box_box_sat(box(t, pairs[2 * p]), box(t, pairs[2 * p + 1]));
}

void box_pair_min_gaps(const double* centres, const double* rotations, const double* half_extents,
                       const long* pairs, long T, long k, long P, double* min_gaps) {
  const BoxBatch box(centres, rotations, half_extents, pairs, T, k, P);
  for (long t = 0; t < T; ++t) {
    double smallest = std::numeric_limits<double>::infinity();
    for (long p = 0; p < P; ++p)  // a pair already farther apart than the closest so far cannot lower it
      smallest = std::min(smallest, box_box_sat(box(t, pairs[2 * p]), box(t, pairs[2 * p + 1]), smallest));
    min_gaps[t] = smallest;
  }
}

}  // namespace snakehead
