#include "snakehead/tracking_fit.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "snakehead/kinematics.hpp"

namespace snakehead {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
using Row4 = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>;

void check_link(const char* what, long link, long links) {
  if (link < 0 || link >= links)
    throw InputError(std::string("TrackingFit: ") + what + " " + std::to_string(link) + " is outside the chain's " +
                     std::to_string(links) + " links");
}

void check_settings(const TrackingSettings& s) {
  const double values[] = {s.damping, s.step_tolerance, s.clearance, s.ground_weight, s.continuity, s.self_clearance,
                           s.self_step};
  for (double v : values)
    if (!std::isfinite(v)) throw InputError("TrackingFit: every setting must be finite");
  if (s.iterations < 0) throw InputError("TrackingFit: iterations must be >= 0");
  if (s.self_step <= 0.0) throw InputError("TrackingFit: self_step must be > 0");
}

}  // namespace

struct TrackingFit::Work {
  Frames local;
  Frames world;                     // the links' world poses at the configuration
  std::vector<double> frames;       // the same, L x 4 x 4 row-major, for the shape queries
  std::vector<double> shifted;      // world frames at a joint moved by self_step
  std::vector<Eigen::Vector3d> axis, joint_origin;  // per lifted joint, world
  std::vector<double> lowest;       // each ground shape's lowest point (G x 3)
  std::vector<long> below_link;     // lifted links below the clearance (their positions in lifted_links)
  std::vector<Eigen::Vector3d> below_point;
  std::vector<double> distance, near_distance, shifted_distance;
  std::vector<long> near;           // the close pairs, flat (2 per pair)
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
};

TrackingFit::TrackingFit(const ChainModel& model, const ShapeSet& shapes, const Eigen::Matrix4d& origin,
                         TrackingSpec spec, TrackingSettings settings)
    : model_(model), shapes_(shapes), spec_(std::move(spec)), settings_(settings) {
  if (!origin.allFinite()) throw InputError("TrackingFit: origin must be finite");
  origin_.matrix() = origin;
  check_settings(settings_);
  const long L = static_cast<long>(model_.links().size());
  const auto& segs = model_.segments();
  for (const auto& s : segs) child_.push_back(model_.link_index(s.link));
  for (int j : spec_.lift) {
    if (j < 0 || j >= model_.n_joints())
      throw InputError("TrackingFit: lifted joint " + std::to_string(j) + " is outside the chain's " +
                       std::to_string(model_.n_joints()) + " joints");
    if (segs[static_cast<std::size_t>(j)].prismatic)
      throw InputError("TrackingFit: lifted joint " + std::to_string(j) + " is prismatic (the fit needs revolute joints)");
  }
  for (long p : spec_.points) check_link("point", p, L);
  if (shapes_.max_frame() >= L) throw InputError("TrackingFit: a shape is attached to a frame the chain does not have");
  for (std::size_t c = 0; c < spec_.lifted_links.size(); ++c) {
    const long k = spec_.lifted_links[c];
    check_link("lifted link", k, L);
    bool any = false;
    for (int s = 0; s < shapes_.size(); ++s)
      if (shapes_.shape(s).frame == k) {
        ground_shapes_.push_back(s);
        ground_owner_.push_back(static_cast<long>(c));
        any = true;
      }
    if (!any) throw InputError("TrackingFit: lifted link " + std::to_string(k) + " has no shapes");
  }
  // lowest_points takes the shapes in any order; keep shape order so that ties resolve as the Python's did
  std::vector<std::size_t> order(ground_shapes_.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return ground_shapes_[a] < ground_shapes_[b]; });
  std::vector<long> shapes_sorted, owner_sorted;
  for (std::size_t i : order) {
    shapes_sorted.push_back(ground_shapes_[i]);
    owner_sorted.push_back(ground_owner_[i]);
  }
  ground_shapes_ = std::move(shapes_sorted);
  ground_owner_ = std::move(owner_sorted);
  for (const auto& p : spec_.self_pairs)
    for (long s : p)
      if (s < 0 || s >= shapes_.size())
        throw InputError("TrackingFit: self pair shape index " + std::to_string(s) + " is outside the set of " +
                         std::to_string(shapes_.size()) + " shapes");
      else
        self_flat_.push_back(s);
}

namespace {

// World poses of the links at q (world_link_frames), as the shape queries' row-major buffer and, given ``world``, as
// Isometries too.
void world_frames(const ChainModel& model, const Eigen::Isometry3d& origin, const Eigen::VectorXd& q, Frames& local,
                  Frames* world, std::vector<double>& out) {
  out.resize(16 * model.links().size());
  world_link_frames(model, origin.matrix(), q, local, out.data());
  if (world == nullptr) return;
  world->resize(model.links().size());  // (local is world_link_frames's work buffer, not one frame per link)
  for (std::size_t k = 0; k < world->size(); ++k) (*world)[k].matrix() = Eigen::Map<const Row4>(out.data() + 16 * k);
}

}  // namespace

// Builds w.r and w.J at q (see the header's comment for the rows).
void TrackingFit::system(const Eigen::VectorXd& q, const Eigen::VectorXd& current, const double* target,
                         Work& w) const {
  const TrackingSettings& s = settings_;
  const auto& segs = model_.segments();
  const long L = static_cast<long>(model_.links().size());
  const long nl = n_lift(), m = n_points();
  world_frames(model_, origin_, q, w.local, &w.world, w.frames);
  w.axis.resize(static_cast<std::size_t>(nl));
  w.joint_origin.resize(static_cast<std::size_t>(nl));
  for (long c = 0; c < nl; ++c) {
    const int j = spec_.lift[static_cast<std::size_t>(c)];
    const Eigen::Isometry3d& frame = w.world[static_cast<std::size_t>(child_[static_cast<std::size_t>(j)])];
    w.axis[c] = frame.linear() * segs[static_cast<std::size_t>(j)].axis;
    w.joint_origin[c] = frame.translation();
  }
  // the ground: each lifted link's lowest point (the lowest of its shapes' lowest points; the first on ties)
  const long G = static_cast<long>(ground_shapes_.size());
  w.lowest.resize(static_cast<std::size_t>(3 * G));
  if (G > 0) lowest_points(w.frames.data(), 1, L, shapes_, ground_shapes_.data(), G, 1, w.lowest.data());
  const std::size_t K = spec_.lifted_links.size();
  std::vector<long> best(K, -1);
  for (long g = 0; g < G; ++g) {
    long& b = best[static_cast<std::size_t>(ground_owner_[g])];
    if (b < 0 || w.lowest[3 * g + 2] < w.lowest[3 * b + 2]) b = g;
  }
  w.below_link.clear();
  w.below_point.clear();
  for (std::size_t c = 0; c < K; ++c) {
    const double* p = w.lowest.data() + 3 * best[c];
    if (p[2] < s.clearance) {
      w.below_link.push_back(static_cast<long>(c));
      w.below_point.emplace_back(p[0], p[1], p[2]);
    }
  }
  // the body: pairs closer than the self clearance (exact there: the cutoff is above it)
  const long P = static_cast<long>(spec_.self_pairs.size());
  w.distance.resize(static_cast<std::size_t>(P));
  w.near.clear();
  w.near_distance.clear();
  if (P > 0) {
    pair_distances(w.frames.data(), 1, L, shapes_, w.frames.data(), 1, L, shapes_, self_flat_.data(), P,
                   2 * s.self_clearance, w.distance.data());
    for (long p = 0; p < P; ++p)
      if (w.distance[p] < s.self_clearance) {
        w.near.push_back(spec_.self_pairs[static_cast<std::size_t>(p)][0]);
        w.near.push_back(spec_.self_pairs[static_cast<std::size_t>(p)][1]);
        w.near_distance.push_back(w.distance[p]);
      }
  }
  const long nb = static_cast<long>(w.below_link.size()), nc = static_cast<long>(w.near_distance.size());
  const long rows = 3 * m + nb + nc + nl;
  w.r.resize(rows);
  w.J.setZero(rows, nl);
  // the point on link k moves with lifted joint c when c's child link is k or before it
  auto moved = [&](long k, long c) {
    return child_[static_cast<std::size_t>(spec_.lift[static_cast<std::size_t>(c)])] <= k;
  };
  for (long i = 0; i < m; ++i) {
    const long k = spec_.points[static_cast<std::size_t>(i)];
    const Eigen::Vector3d x = w.world[static_cast<std::size_t>(k)].translation();
    w.r.segment<3>(3 * i) = x - Eigen::Map<const Eigen::Vector3d>(target + 3 * i);
    for (long c = 0; c < nl; ++c)
      if (moved(k, c)) w.J.block<3, 1>(3 * i, c) = w.axis[c].cross(x - w.joint_origin[c]);
  }
  long row = 3 * m;
  for (long b = 0; b < nb; ++b, ++row) {
    const long k = spec_.lifted_links[static_cast<std::size_t>(w.below_link[b])];
    const Eigen::Vector3d& x = w.below_point[b];
    w.r[row] = s.ground_weight * (x.z() - s.clearance);
    for (long c = 0; c < nl; ++c)
      if (moved(k, c)) w.J(row, c) = s.ground_weight * w.axis[c].cross(x - w.joint_origin[c]).z();
  }
  if (nc > 0) {
    w.shifted_distance.resize(static_cast<std::size_t>(nc));
    Eigen::VectorXd qh = q;
    for (long c = 0; c < nl; ++c) {
      const int j = spec_.lift[static_cast<std::size_t>(c)];
      qh[j] = q[j] + s.self_step;
      world_frames(model_, origin_, qh, w.local, nullptr, w.shifted);
      pair_distances(w.shifted.data(), 1, L, shapes_, w.shifted.data(), 1, L, shapes_, w.near.data(), nc, kInf,
                     w.shifted_distance.data());
      for (long p = 0; p < nc; ++p)
        w.J(row + p, c) = s.ground_weight * ((w.shifted_distance[p] - w.near_distance[p]) / s.self_step);
      qh[j] = q[j];
    }
    for (long p = 0; p < nc; ++p) w.r[row + p] = s.ground_weight * (w.near_distance[p] - s.self_clearance);
    row += nc;
  }
  for (long c = 0; c < nl; ++c, ++row) {
    w.r[row] = s.continuity * (q[spec_.lift[static_cast<std::size_t>(c)]] - current[c]);
    w.J(row, c) = s.continuity;
  }
}

namespace {

Eigen::VectorXd damped_step(const Eigen::MatrixXd& J, const Eigen::VectorXd& r, double damping) {
  Eigen::MatrixXd A = J.transpose() * J;
  A.diagonal().array() += damping * damping;
  return -A.llt().solve(J.transpose() * r);
}

}  // namespace

TrackingStep TrackingFit::step(const Eigen::VectorXd& q, const Eigen::VectorXd& current, const double* target) const {
  model_.check_configuration(q);
  if (current.size() != n_lift() || !current.allFinite())
    throw InputError("TrackingFit.step: current must have one finite entry per lifted joint");
  Work w;
  system(q, current, target, w);
  return {w.r, w.J, damped_step(w.J, w.r, settings_.damping)};
}

void TrackingFit::fit(double* q, long S, const double* targets) const {
  const long n = n_joints(), nl = n_lift(), m = n_points();
  if (S < 0) throw InputError("TrackingFit.fit: negative sample count");
  for (long i = 0; i < S * n; ++i)
    if (!std::isfinite(q[i])) throw InputError("TrackingFit.fit: q must be finite");
  for (long i = 0; i < S * m * 3; ++i)
    if (!std::isfinite(targets[i])) throw InputError("TrackingFit.fit: targets must be finite");
  if (S < 3 || nl == 0) return;  // nothing to fit
  const Eigen::VectorXd& lo = model_.lower();
  const Eigen::VectorXd& hi = model_.upper();
  Work w;
  Eigen::VectorXd current(nl), qj(n);
  for (long c = 0; c < nl; ++c) current[c] = q[spec_.lift[static_cast<std::size_t>(c)]];
  for (long t = 1; t + 1 < S; ++t) {
    qj = Eigen::Map<const Eigen::VectorXd>(q + t * n, n);
    for (long c = 0; c < nl; ++c) qj[spec_.lift[static_cast<std::size_t>(c)]] = current[c];
    for (int it = 0; it < settings_.iterations; ++it) {
      system(qj, current, targets + t * m * 3, w);
      const Eigen::VectorXd dq = damped_step(w.J, w.r, settings_.damping);
      for (long c = 0; c < nl; ++c) {
        const int j = spec_.lift[static_cast<std::size_t>(c)];
        qj[j] = std::min(std::max(qj[j] + dq[c], lo[j]), hi[j]);  // as np.clip
      }
      if (dq.cwiseAbs().maxCoeff() < settings_.step_tolerance) break;
    }
    Eigen::Map<Eigen::VectorXd>(q + t * n, n) = qj;
    for (long c = 0; c < nl; ++c) current[c] = qj[spec_.lift[static_cast<std::size_t>(c)]];
  }
}

}  // namespace snakehead
