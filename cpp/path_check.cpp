#include "snakehead/path_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

#include "snakehead/kinematics.hpp"
#include "snakehead/parallel_for.hpp"
#include "snakehead/support.hpp"

namespace snakehead {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Samples of zmp_check below which another thread costs more than it saves (a thread starts in ~20-50 us; a
// sample's frames, momenta and lowest points take ~1 us).
constexpr long kZmpSamplesPerThread = 256;
// Samples zmp_check takes at a time (its per-sample buffers: lowest points and contact keys, ~0.5 MB).
constexpr long kZmpBlock = 8192;
using Row4 = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>;

using ItemKind = PathChecker::ItemKind;

// Intervals are not split deeper than this many times (a floor_step of 0 would otherwise recurse without end).
constexpr int kMaxDepth = 40;

void check_index(const char* what, long index, const ShapeSet& set) {
  if (index < 0 || index >= set.size())
    throw InputError(std::string("PathChecker: ") + what + " shape index " + std::to_string(index) +
                     " is outside the set of " + std::to_string(set.size()) + " shapes");
}

}  // namespace

bool PathVerdict::clear() const {
  return std::all_of(segment_clear.begin(), segment_clear.end(), [](unsigned char c) { return c != 0; });
}

PathChecker::PathChecker(const ChainModel& model, const ShapeSet& shapes, const Eigen::Matrix4d& origin,
                         PathCheckSpec spec, const ShapeSet* obstacles)
    : model_(model), shapes_(shapes), obstacles_(obstacles), spec_(std::move(spec)) {
  if (!origin.allFinite()) throw InputError("PathChecker: origin must be finite");
  origin_.matrix() = origin;
  if (std::isnan(spec_.ground_floor) || std::isnan(spec_.obstacle_cutoff))
    throw InputError("PathChecker: ground_floor and obstacle_cutoff must not be NaN");
  const auto& segs = model_.segments();
  const int n = model_.n_joints();
  for (const auto& s : segs)
    if (s.prismatic) throw InputError("PathChecker: prismatic joints are not supported (the motion bound needs revolute joints)");
  if (shapes_.max_frame() >= static_cast<int>(model_.links().size()))
    throw InputError("PathChecker: a shape is attached to a frame the chain does not have");
  if (obstacles_ != nullptr && obstacles_->max_frame() > 0)
    throw InputError("PathChecker: obstacle shapes must all be on frame 0 (the world)");
  // arm[m]: |o_{m+1} - o_m|, constant for revolute joints (o_{m+1} in joint m's frame is (post_m pre_{m+1})'s origin)
  std::vector<double> arm(static_cast<std::size_t>(std::max(n - 1, 0)));
  for (int m = 0; m + 1 < n; ++m) arm[m] = (segs[m].post * segs[m + 1].pre).translation().norm();
  const auto& links = model_.links();
  joint_of_shape_.resize(static_cast<std::size_t>(shapes_.size()));
  reach_.assign(static_cast<std::size_t>(shapes_.size()), std::vector<double>(static_cast<std::size_t>(n), kInf));
  for (int s = 0; s < shapes_.size(); ++s) {
    const LinkInfo& link = links[static_cast<std::size_t>(shapes_.shape(s).frame)];
    const int k = link.segment;
    joint_of_shape_[s] = k;
    if (k < 0) continue;
    // the bounding sphere's centre in joint k's frame (its distance from o_k is constant)
    const Eigen::Vector3d c = segs[k].post * link.offset * shapes_.shape(s).origin * shapes_.geometry(s).sphere_centre;
    double along = c.norm();
    for (int i = k; i >= 0; --i) {
      reach_[s][i] = along;
      if (i > 0) along += arm[i - 1];
    }
  }
  for (long s : spec_.ground_shapes) {
    check_index("ground", s, shapes_);
    items_.push_back({ItemKind::Ground, s, -1});
  }
  for (const auto& p : spec_.self_pairs) {
    check_index("self pair", p[0], shapes_);
    check_index("self pair", p[1], shapes_);
    // the earlier shape first: the pair's bound counts the joints between them
    const bool swap = joint_of_shape_[p[0]] > joint_of_shape_[p[1]];
    items_.push_back({ItemKind::Self, swap ? p[1] : p[0], swap ? p[0] : p[1]});
  }
  for (const auto& p : spec_.obstacle_pairs) {
    if (obstacles_ == nullptr) throw InputError("PathChecker: obstacle pairs given without obstacles");
    check_index("obstacle pair", p[0], shapes_);
    check_index("obstacle pair", p[1], *obstacles_);
    items_.push_back({ItemKind::Obstacle, p[0], p[1]});
  }
}

void PathChecker::world_frames(const Eigen::VectorXd& q, double* out) const {
  Frames f;
  world_frames(q, out, f);
}

void PathChecker::world_frames(const Eigen::VectorXd& q, double* out, Frames& f) const {
  world_link_frames(model_, origin_.matrix(), q, f, out);
}

void PathChecker::joints_at(const Eigen::VectorXd& q, Joints& out, std::vector<double>& frames) const {
  model_.check_configuration(q);
  frames.resize(static_cast<std::size_t>(16 * links()));
  world_frames(q, frames.data());
  const auto& segs = model_.segments();
  out.axis.resize(segs.size());
  out.origin.resize(segs.size());
  Eigen::Isometry3d frame = origin_;
  for (std::size_t i = 0; i < segs.size(); ++i) {
    const Eigen::Isometry3d joint = frame * segs[i].pre;  // the rotation about the axis keeps both
    out.axis[i] = joint.linear() * segs[i].axis;
    out.origin[i] = joint.translation();
    frame = joint * Eigen::AngleAxisd(q[static_cast<Eigen::Index>(i)], segs[i].axis) * segs[i].post;
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Per-sample minima.

SampleClearances PathChecker::sample(const double* qs, long T) const {
  if (T < 0) throw InputError("PathChecker.sample: negative sample count");
  const long n = model_.n_joints(), L = links();
  SampleClearances out;
  out.ground.assign(static_cast<std::size_t>(T), kInf);
  out.self.assign(static_cast<std::size_t>(T), kInf);
  out.obstacle.assign(static_cast<std::size_t>(T), kInf);
  std::vector<long> self_pairs, obstacle_pairs;
  for (const auto& p : spec_.self_pairs) self_pairs.insert(self_pairs.end(), {p[0], p[1]});
  for (const auto& p : spec_.obstacle_pairs) obstacle_pairs.insert(obstacle_pairs.end(), {p[0], p[1]});
  const long G = static_cast<long>(spec_.ground_shapes.size());
  constexpr long kBlock = 256;  // samples whose frames are held at once
  std::vector<double> frames(static_cast<std::size_t>(16 * L * kBlock)), low(static_cast<std::size_t>(G * kBlock));
  const Eigen::Matrix4d world = Eigen::Matrix4d::Identity();
  Frames work;
  for (long t0 = 0; t0 < T; t0 += kBlock) {
    const long B = std::min(kBlock, T - t0);
    for (long t = 0; t < B; ++t) {
      const Eigen::Map<const Eigen::VectorXd> q(qs + (t0 + t) * n, n);
      model_.check_configuration(q);
      world_frames(q, frames.data() + 16 * L * t, work);
    }
    if (G > 0) {
      lowest_z(frames.data(), B, L, shapes_, spec_.ground_shapes.data(), G, low.data());
      for (long t = 0; t < B; ++t)
        out.ground[t0 + t] = *std::min_element(low.begin() + t * G, low.begin() + (t + 1) * G);
    }
    if (!self_pairs.empty())
      pair_min_distances(frames.data(), B, L, shapes_, frames.data(), B, L, shapes_, self_pairs.data(),
                         static_cast<long>(self_pairs.size() / 2), kInf, out.self.data() + t0);
    if (!obstacle_pairs.empty())
      pair_min_distances(frames.data(), B, L, shapes_, world.data(), 1, 1, *obstacles_, obstacle_pairs.data(),
                         static_cast<long>(obstacle_pairs.size() / 2), spec_.obstacle_cutoff,
                         out.obstacle.data() + t0);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------------------------
// The motion bound (see the header).

namespace {

// Distance of point p to the line through o along unit a.
double axis_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& o, const Eigen::Vector3d& a) {
  return a.cross(p - o).norm();
}

// A configuration evaluated lazily: its frames and joints at once, each item's lower bound (cheap) or exact value
// when first asked.
class Sample {
 public:
  Sample() = default;
  Eigen::VectorXd q;
  std::vector<double> frames;
  std::vector<Eigen::Vector3d> centre;    // world bounding-sphere centre per robot shape
  std::vector<double> lower;              // per item: a lower bound of its value (exact once exact[i])
  std::vector<unsigned char> exact;
  std::vector<Eigen::Vector3d> axis, origin;  // world joint axes and origins
};

}  // namespace

// ---------------------------------------------------------------------------------------------------------------
// The proof over a path.

class PathProof {
 public:
  PathProof(const PathChecker& c, const PathOptions& o) : c_(c), o_(o) {}

  PathVerdict run(const double* waypoints, long K) {
    const long n = c_.model_.n_joints();
    if (K < 1) throw InputError("check_path: at least one waypoint is needed");
    if (!(o_.first_step > 0.0) || !(o_.floor_step >= 0.0) || !std::isfinite(o_.first_step))
      throw InputError("check_path: first_step must be finite and > 0, floor_step >= 0");
    v_.segment_clear.assign(static_cast<std::size_t>(K - 1), 0);
    Sample prev = evaluate(Eigen::Map<const Eigen::VectorXd>(waypoints, n));
    if (K == 1) single(prev);
    for (long w = 0; w + 1 < K && !stopped_; ++w) {
      Sample next = evaluate(Eigen::Map<const Eigen::VectorXd>(waypoints + (w + 1) * n, n));
      v_.segment_clear[w] = segment(prev, next) ? 1 : 0;
      prev = std::move(next);
    }
    return v_;
  }

  enum class Status { Clear, Split, Violated };

  Sample evaluate(const Eigen::VectorXd& q) {
    Sample s;
    s.q = q;
    PathChecker::Joints j;
    c_.joints_at(q, j, s.frames);
    s.axis = std::move(j.axis);
    s.origin = std::move(j.origin);
    ++v_.samples;
    const int S = c_.shapes_.size();
    s.centre.resize(static_cast<std::size_t>(S));
    for (int i = 0; i < S; ++i) s.centre[i] = pose(s, i) * c_.shapes_.geometry(i).sphere_centre;
    s.lower.resize(c_.items_.size());
    s.exact.assign(c_.items_.size(), 0);
    for (std::size_t i = 0; i < c_.items_.size(); ++i) s.lower[i] = cheap(s, c_.items_[i], s.exact[i]);
    return s;
  }

 private:
  Eigen::Isometry3d pose(const Sample& s, long shape) const {
    Eigen::Isometry3d frame;
    frame.matrix() = Eigen::Map<const Row4>(s.frames.data() + 16 * c_.shapes_.shape(static_cast<int>(shape)).frame);
    return frame * c_.shapes_.shape(static_cast<int>(shape)).origin;
  }

  // The item's lower bound from the bounding spheres (exact for the ground: it is a closed form).
  double cheap(const Sample& s, const PathChecker::Item& it, unsigned char& exact) {
    if (it.kind == ItemKind::Ground) {
      double z = 0.0;
      lowest_z(s.frames.data(), 1, c_.links(), c_.shapes_, &it.a, 1, &z);
      exact = 1;
      note(it, z);
      return z;
    }
    const ShapeGeometry& ga = c_.shapes_.geometry(static_cast<int>(it.a));
    if (it.kind == ItemKind::Self) {
      const ShapeGeometry& gb = c_.shapes_.geometry(static_cast<int>(it.b));
      return (s.centre[it.a] - s.centre[it.b]).norm() - ga.sphere_radius - gb.sphere_radius;
    }
    const ShapeGeometry& gb = c_.obstacles_->geometry(static_cast<int>(it.b));
    const Eigen::Vector3d cb = c_.obstacles_->shape(static_cast<int>(it.b)).origin * gb.sphere_centre;
    return (s.centre[it.a] - cb).norm() - ga.sphere_radius - gb.sphere_radius;
  }

  double exact(Sample& s, std::size_t i) {
    if (s.exact[i]) return s.lower[i];
    const PathChecker::Item& it = c_.items_[i];
    const Eigen::Isometry3d pa = pose(s, it.a);
    double d;
    if (it.kind == ItemKind::Self)
      d = shape_signed_distance(c_.shapes_, static_cast<int>(it.a), pa, c_.shapes_, static_cast<int>(it.b), pose(s, it.b));
    else
      d = shape_signed_distance(c_.shapes_, static_cast<int>(it.a), pa, *c_.obstacles_, static_cast<int>(it.b),
                                c_.obstacles_->shape(static_cast<int>(it.b)).origin);
    s.exact[i] = 1;
    s.lower[i] = d;
    note(it, d);
    return d;
  }

  void note(const PathChecker::Item& it, double d) {
    double& m = it.kind == ItemKind::Ground ? v_.ground : it.kind == ItemKind::Self ? v_.self : v_.obstacle;
    m = std::min(m, d);
  }

  bool passes(const PathChecker::Item& it, double value) const {
    return it.kind == ItemKind::Ground ? value >= c_.spec_.ground_floor : value > 0.0;
  }

  // A single configuration: clear when every item passes exactly.
  void single(Sample& s) {
    for (std::size_t i = 0; i < c_.items_.size(); ++i)
      if (!passes(c_.items_[i], s.lower[i]) && !passes(c_.items_[i], exact(s, i))) ++v_.violations;
  }

  // The interval a -> b along which joint j travels at most dq[j]; obstacle_ is left at the smallest lower bound of
  // the obstacle distances over it (the cone bound, or the value at a violated end).
  Status interval(Sample& a, Sample& b, const Eigen::VectorXd& dq) {
    bounds(a, b, dq, B_, Z_);
    bool split = false, violated = false;
    obstacle_ = kInf;
    for (std::size_t i = 0; i < c_.items_.size(); ++i) {
      const PathChecker::Item& it = c_.items_[i];
      const double bound = it.kind == ItemKind::Ground ? Z_[it.a] : it.kind == ItemKind::Obstacle ? B_[it.a] : pair_[i];
      const double cone = 0.5 * (a.lower[i] + b.lower[i] - bound);
      if (passes(it, cone)) {
        if (it.kind == ItemKind::Obstacle) obstacle_ = std::min(obstacle_, cone);
        continue;
      }
      const double ea = exact(a, i), eb = exact(b, i);
      if (it.kind == ItemKind::Obstacle) obstacle_ = std::min(obstacle_, std::min(0.5 * (ea + eb - bound), std::min(ea, eb)));
      if (!passes(it, ea) || !passes(it, eb)) {
        if (!complete_) return Status::Violated;
        violated = true;  // a motion's other items are still bounded (obstacle_ covers them all)
      } else if (!passes(it, 0.5 * (ea + eb - bound)))
        split = true;
    }
    return violated ? Status::Violated : split ? Status::Split : Status::Clear;
  }

 public:
  // The motion bounds of the straight segment a -> b (see the header): B_S and Z_S per robot shape, and each self
  // pair's bound (pair_), the sum over the joints between the pair's links only.
  // dq[j]: how far joint j travels between a and b (|b.q - a.q| along a straight segment, the total variation
  // along a motion).
  void bounds(const Sample& a, const Sample& b, const Eigen::VectorXd& dq, std::vector<double>& B,
              std::vector<double>& Z) {
    const int S = c_.shapes_.size(), n = c_.model_.n_joints();
    B.assign(static_cast<std::size_t>(S), 0.0);
    Z.assign(static_cast<std::size_t>(S), 0.0);
    turned_.assign(static_cast<std::size_t>(n) + 1, 0.0);  // turned_[j]: sum_{i < j} |dq_i|
    for (int j = 0; j < n; ++j) turned_[j + 1] = turned_[j] + dq[j];
    radius_.assign(static_cast<std::size_t>(S * n), 0.0);  // r_{j,S} + rho
    for (int s = 0; s < S; ++s) {
      const double rho = c_.shapes_.geometry(s).sphere_radius;
      double relative = 0.0;  // sum_{j < i <= k} |dq_i| reach(i, S), built from the last joint back
      for (int j = c_.joint_of_shape_[s]; j >= 0; --j) {
        const double d = std::min(axis_distance(a.centre[s], a.origin[j], a.axis[j]),
                                  axis_distance(b.centre[s], b.origin[j], b.axis[j]));
        const double r = std::min(d + relative, c_.reach_[s][j]) + rho;
        const double tilt = std::min(1.0, std::min(a.axis[j].head<2>().norm(), b.axis[j].head<2>().norm()) + turned_[j]);
        radius_[static_cast<std::size_t>(s * n + j)] = r;
        B[s] += dq[j] * r;
        Z[s] += dq[j] * tilt * r;
        relative += dq[j] * c_.reach_[s][j];
      }
    }
    pair_.assign(c_.items_.size(), 0.0);
    for (std::size_t i = 0; i < c_.items_.size(); ++i) {
      const PathChecker::Item& it = c_.items_[i];
      if (it.kind != ItemKind::Self) continue;
      // in the earlier link's frame only the joints after it move the later shape, each about the same axis
      // distance (frame-invariant) but with the relative term counting the joints after j only: r_{j,S2} holds
      double sum = 0.0;
      for (int j = c_.joint_of_shape_[it.b]; j > c_.joint_of_shape_[it.a]; --j)
        sum += dq[j] * radius_[static_cast<std::size_t>(it.b * n + j)];
      pair_[i] = sum;
    }
  }

 private:
  // Proves [a, b]; splits it (down to the floor) where the bound is too loose.
  bool prove(Sample& a, Sample& b, int depth) {
    const Status s = interval(a, b, (b.q - a.q).cwiseAbs());
    if (s != Status::Split) leaf_obstacle_ = std::min(leaf_obstacle_, obstacle_);
    if (s == Status::Clear) {
      ++v_.proven;
      return true;
    }
    if (s == Status::Violated) {
      ++v_.violations;
      stopped_ = o_.stop_at_violation;
      return false;
    }
    if ((b.q - a.q).cwiseAbs().maxCoeff() <= o_.floor_step || depth >= kMaxDepth) {
      ++v_.unproven;
      leaf_obstacle_ = std::min(leaf_obstacle_, obstacle_);
      return false;
    }
    Sample mid = evaluate(0.5 * (a.q + b.q));
    const bool left = prove(a, mid, depth + 1);
    if (stopped_) return false;
    const bool right = prove(mid, b, depth + 1);
    return left && right;
  }

  // The segment a -> b, first sampled at most first_step apart.
  bool segment(Sample& a, Sample& b) {
    const double step = (b.q - a.q).cwiseAbs().maxCoeff();
    const long pieces = std::max(1L, static_cast<long>(std::ceil(step / o_.first_step - 1e-9)));
    bool clear = true;
    Sample left = a;
    for (long p = 1; p <= pieces && !stopped_; ++p) {
      Sample right = p == pieces ? b : evaluate(a.q + (static_cast<double>(p) / pieces) * (b.q - a.q));
      clear = prove(left, right, 0) && clear;
      if (p == pieces) b = right;  // keeps the exact values computed at b for the next segment
      left = std::move(right);
    }
    return clear && !stopped_;
  }

  // ---- a sampled motion (check_motion) ----

 public:
  MotionVerdict run_motion(const double* qs, long T) {
    const long n = c_.model_.n_joints();
    if (T < 1) throw InputError("check_motion: at least one sample is needed");
    if (!(o_.first_step > 0.0) || !(o_.floor_step >= 0.0) || !std::isfinite(o_.first_step))
      throw InputError("check_motion: first_step must be finite and > 0, floor_step >= 0");
    qs_ = qs;
    complete_ = true;
    // travel_(k, j): joint j's total variation from sample 0 to sample k along the straight segments
    travel_.resize(T, n);
    travel_.row(0).setZero();
    for (long k = 1; k < T; ++k)
      for (long j = 0; j < n; ++j) travel_(k, j) = travel_(k - 1, j) + std::abs(qs[k * n + j] - qs[(k - 1) * n + j]);
    lower_.assign(static_cast<std::size_t>(T), kInf);
    Sample prev = evaluate(row(0));
    if (T == 1) single(prev);
    lower_[0] = obstacle_at(prev);
    long a = 0;
    while (a + 1 < T) {
      long b = a + 1;  // the next sample to evaluate: where some joint has travelled first_step since a
      while (b + 1 < T && (travel_.row(b + 1) - travel_.row(a)).maxCoeff() <= o_.first_step) ++b;
      Sample next = evaluate(row(b));
      motion(a, b, prev, next);
      prev = std::move(next);
      a = b;
    }
    lower_[static_cast<std::size_t>(T - 1)] = std::min(lower_[static_cast<std::size_t>(T - 1)], obstacle_at(prev));
    MotionVerdict out;
    out.samples = v_.samples;
    out.proven = v_.proven;
    out.unproven = v_.unproven;
    out.violations = v_.violations;
    out.ground = v_.ground;
    out.self = v_.self;
    out.obstacle = v_.obstacle;
    out.obstacle_lower = std::move(lower_);
    return out;
  }

 private:
  Eigen::Map<const Eigen::VectorXd> row(long k) const {
    const long n = c_.model_.n_joints();
    return Eigen::Map<const Eigen::VectorXd>(qs_ + k * n, n);
  }

  // The smallest obstacle value known at an evaluated sample (exact where its cheap bound is below the cutoff, as
  // PathChecker::sample reports it).
  double obstacle_at(Sample& s) {
    double m = kInf;
    for (std::size_t i = 0; i < c_.items_.size(); ++i) {
      if (c_.items_[i].kind != ItemKind::Obstacle) continue;
      m = std::min(m, s.lower[i] < c_.spec_.obstacle_cutoff ? exact(s, i) : s.lower[i]);
    }
    return m;
  }

  // Samples a..b (evaluated: sa, sb) of the motion: proven with the joints' total variation, else halved by sample
  // index; two consecutive samples are proven along their straight segment (prove). Writes lower_[a..b-1].
  void motion(long a, long b, Sample& sa, Sample& sb) {
    const Eigen::VectorXd dq = (travel_.row(b) - travel_.row(a)).transpose();
    const Status s = interval(sa, sb, dq);
    if (s == Status::Clear || s == Status::Violated) {
      if (s == Status::Clear) ++v_.proven; else ++v_.violations;
      for (long k = a; k < b; ++k) lower_[static_cast<std::size_t>(k)] = obstacle_;
      return;
    }
    if (b == a + 1) {
      leaf_obstacle_ = kInf;
      const bool clear = prove(sa, sb, 0);
      lower_[static_cast<std::size_t>(a)] = clear ? leaf_obstacle_ : std::min(leaf_obstacle_, 0.0);
      return;
    }
    const long m = a + (b - a) / 2;
    Sample mid = evaluate(row(m));
    motion(a, m, sa, mid);
    motion(m, b, mid, sb);
  }

  const PathChecker& c_;
  const PathOptions& o_;
  PathVerdict v_;
  bool stopped_ = false;
  std::vector<double> B_, Z_, pair_, turned_, radius_;
  double obstacle_ = kInf, leaf_obstacle_ = kInf;
  bool complete_ = false;  // interval() bounds every item, also after a violated one (check_motion)
  const double* qs_ = nullptr;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> travel_;
  std::vector<double> lower_;
};

PathVerdict PathChecker::check_path(const double* waypoints, long K, const PathOptions& options) const {
  return PathProof(*this, options).run(waypoints, K);
}

MotionVerdict PathChecker::check_motion(const double* qs, long T, const PathOptions& options) const {
  PathOptions o = options;
  o.stop_at_violation = false;  // every interval is reported (obstacle_lower)
  return PathProof(*this, o).run_motion(qs, T);
}

void PathChecker::motion_bounds(const Eigen::VectorXd& qa, const Eigen::VectorXd& qb, std::vector<double>& B,
                                std::vector<double>& Z) const {
  const PathOptions options;
  PathProof proof(*this, options);
  proof.bounds(proof.evaluate(qa), proof.evaluate(qb), (qb - qa).cwiseAbs(), B, Z);
}

// ---------------------------------------------------------------------------------------------------------------
// The ZMP check.

void time_derivative(const double* t, const double* x, long T, long m, double* out) {
  if (T < 2) throw InputError("time_derivative: at least two samples are needed");
  if (T == 2) {
    for (long c = 0; c < m; ++c) out[c] = out[m + c] = (x[m + c] - x[c]) / (t[1] - t[0]);
    return;
  }
  for (long k = 1; k + 1 < T; ++k) {  // numpy.gradient's second-order differences on uneven steps
    const double h1 = t[k] - t[k - 1], h2 = t[k + 1] - t[k];
    const double a = -h2 / (h1 * (h1 + h2)), b = (h2 - h1) / (h1 * h2), c = h1 / (h2 * (h1 + h2));
    for (long j = 0; j < m; ++j) out[k * m + j] = a * x[(k - 1) * m + j] + b * x[k * m + j] + c * x[(k + 1) * m + j];
  }
  {
    const double h1 = t[1] - t[0], h2 = t[2] - t[1];
    const double a = -(2.0 * h1 + h2) / (h1 * (h1 + h2)), b = (h1 + h2) / (h1 * h2), c = -h1 / (h2 * (h1 + h2));
    for (long j = 0; j < m; ++j) out[j] = a * x[j] + b * x[m + j] + c * x[2 * m + j];
  }
  {
    const double h1 = t[T - 2] - t[T - 3], h2 = t[T - 1] - t[T - 2];
    const double a = h2 / (h1 * (h1 + h2)), b = -(h2 + h1) / (h1 * h2), c = (2.0 * h2 + h1) / (h2 * (h1 + h2));
    for (long j = 0; j < m; ++j)
      out[(T - 1) * m + j] = a * x[(T - 3) * m + j] + b * x[(T - 2) * m + j] + c * x[(T - 1) * m + j];
  }
}

namespace {

// The contact configuration a sample belongs to (see ZmpCheckSpec): the rounded key joints (np.round(q, 12)) and,
// for contact "ground", the last link touching the ground; `low` holds the contact shapes' lowest z.
void contact_key(const ZmpCheckSpec& spec, const std::vector<int>& child, const ShapeSet& shapes, const double* low,
                 const double* q, std::vector<double>& key) {
  key.clear();
  const auto rounded = [](double v) { return std::nearbyint(v * 1e12) / 1e12; };
  if (!spec.ground_key) {
    for (int j : spec.key_joints) key.push_back(rounded(q[j]));
    return;
  }
  int last = -1;
  for (std::size_t i = 0; i < spec.contact_shapes.size(); ++i)
    if (low[i] <= spec.tolerance) last = std::max(last, shapes.shape(static_cast<int>(spec.contact_shapes[i])).frame);
  for (std::size_t j = 0; j < child.size(); ++j) key.push_back(child[j] <= last ? rounded(q[j]) : 0.0);
  key.push_back(last);
}

using Points = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;

// The runs' support polygons, one after the other (their vertices counter-clockwise, flat x, y), and the buffers that
// build them, allocated once for all the runs of a check.
//
// Runs follow each other sample by sample where links on the ground move (a neck lifting off it: ~3000 runs in a
// lift of 4000 samples), while most contact shapes (the base's) lie still. The hull of the contact points is
// therefore built from a kept part: the hull of the touching points of the shapes that lay still between two runs,
// kept while their links' world frames stay the same to the bit (their points then are the same), and the points of
// the other near shapes. The hull of a set is the hull of its hull's vertices and the other points, so the polygon is
// the same (the monotone chain may differ only where it drops a vertex as collinear, by a sine of 1e-9, or as
// coincident, 1e-12 m: the margins then differ by as little).
class SupportRuns {
 public:
  SupportRuns(const ZmpCheckSpec& spec, const ShapeSet& shapes, long L)
      : spec_(spec), shapes_(shapes), near_(spec.contact_shapes.size()),
        count_(static_cast<long>(spec.contact_shapes.size()) * spec.points_per_shape),
        points_(static_cast<std::size_t>(3 * count_)), touching_(count_, 2), kept_points_(count_, 2),
        previous_(static_cast<std::size_t>(16 * L)), kept_frames_(static_cast<std::size_t>(16 * L)),
        kept_shape_(spec.contact_shapes.size(), 0), still_(spec.contact_shapes.size(), 0) {
    start_.push_back(0);
  }

  // Adds the polygon of a new run: the convex hull of the contact points touching the ground (tolerance) at the
  // sample whose world frames are `frames`; `low`: the contact shapes' lowest z there. A shape whose lowest z is
  // above the tolerance (by more than round-off) has no point touching: its candidates are not computed.
  void add(const double* frames, long L, const double* low) {
    const std::size_t S = spec_.contact_shapes.size();
    const bool reuse = has_kept_ && kept_still(frames);
    near_.clear();
    near_index_.clear();
    for (std::size_t i = 0; i < S; ++i)
      if (low[i] <= spec_.tolerance + kRoundOff && !(reuse && kept_shape_[i])) {
        near_.push_back(spec_.contact_shapes[i]);
        near_index_.push_back(static_cast<long>(i));
      }
    const long k = static_cast<long>(near_.size());
    lowest_points(frames, 1, L, shapes_, near_.data(), k, spec_.points_per_shape, points_.data());
    long m = 0;
    if (reuse)  // the kept hull's vertices, then the other shapes' touching points
      for (long v = 0; v < kept_count_; ++v) touching_.row(m++) = kept_points_.row(v);
    for (long p = 0; p < k * spec_.points_per_shape; ++p)
      if (points_[3 * p + 2] <= spec_.tolerance) touching_.row(m++) << points_[3 * p], points_[3 * p + 1];
    convex_hull_into(touching_.topRows(m), work_, hull_);
    for (int v : hull_) vertices_.insert(vertices_.end(), {touching_(v, 0), touching_(v, 1)});
    start_.push_back(static_cast<long>(vertices_.size() / 2));
    if (!reuse) keep_still_part(frames, L, k);
    std::copy(frames, frames + 16 * L, previous_.begin());
    has_previous_ = true;
  }

  long runs() const { return static_cast<long>(start_.size()) - 1; }

  // The runs of a kept prefix (ZmpPrefix) in place of these.
  void restore(const std::vector<double>& vertices, const std::vector<long>& start) {
    vertices_ = vertices;
    start_ = start;
  }

  // Every polygon so far turned by (c, s) about the origin and moved by (x, y) (a kept prefix made at another
  // placement of the base on the ground).
  void move(double c, double s, double x, double y) {
    for (std::size_t v = 0; v + 1 < vertices_.size(); v += 2) {
      const double vx = vertices_[v], vy = vertices_[v + 1];
      vertices_[v] = c * vx - s * vy + x;
      vertices_[v + 1] = s * vx + c * vy + y;
    }
  }

  // The first `runs` runs' polygons into vertices and start (as ZmpPrefix holds them).
  void keep(long runs, std::vector<double>& vertices, std::vector<long>& start) const {
    start.assign(start_.begin(), start_.begin() + runs + 1);
    vertices.assign(vertices_.begin(), vertices_.begin() + 2 * start.back());
  }

  // The signed distance of xy to run r's polygon (hull_margin, the hull not built again).
  double margin(long r, const Eigen::Vector2d& xy) const {
    return convex_margin(vertices_.data() + 2 * start_[r], start_[r + 1] - start_[r], xy);
  }

 private:
  static constexpr double kRoundOff = 1e-9;  // m: lowest_z and the candidate points' z agree far closer

  // Link l's world frame is the same, to the bit, in frames a and b.
  static bool same_frame(const double* a, const double* b, int l) {
    return std::memcmp(a + 16 * l, b + 16 * l, 12 * sizeof(double)) == 0;  // (the last row is always 0 0 0 1)
  }

  // Every kept shape's link lies where it lay when the kept hull was made.
  bool kept_still(const double* frames) const {
    for (std::size_t i = 0; i < kept_shape_.size(); ++i)
      if (kept_shape_[i] && !same_frame(frames, kept_frames_.data(), link_of(i))) return false;
    return true;
  }

  int link_of(std::size_t i) const { return shapes_.shape(static_cast<int>(spec_.contact_shapes[i])).frame; }

  // After a polygon built from all the k near shapes (near_, their points in points_): keeps the hull of the touching
  // points of those whose links did not move since the previous run (none kept when none did, or all did not).
  void keep_still_part(const double* frames, long L, long k) {
    has_kept_ = false;
    if (!has_previous_) return;
    long still = 0;
    for (long j = 0; j < k; ++j) {
      const std::size_t i = static_cast<std::size_t>(near_index_[static_cast<std::size_t>(j)]);
      still_[i] = same_frame(frames, previous_.data(), link_of(i));
      still += still_[i];
    }
    if (still == 0 || still == k) return;  // nothing to keep, or nothing else to add to it
    long m = 0;
    std::fill(kept_shape_.begin(), kept_shape_.end(), 0);
    for (long j = 0; j < k; ++j) {
      const std::size_t i = static_cast<std::size_t>(near_index_[static_cast<std::size_t>(j)]);
      if (!still_[i]) continue;
      kept_shape_[i] = 1;
      for (long c = 0; c < spec_.points_per_shape; ++c) {
        const double* point = &points_[3 * (j * spec_.points_per_shape + c)];
        if (point[2] <= spec_.tolerance) kept_points_.row(m++) << point[0], point[1];
      }
    }
    convex_hull_into(kept_points_.topRows(m), work_, hull_);
    for (std::size_t v = 0; v < hull_.size(); ++v) touching_.row(static_cast<Eigen::Index>(v)) = kept_points_.row(hull_[v]);
    kept_count_ = static_cast<long>(hull_.size());
    kept_points_.topRows(kept_count_) = touching_.topRows(kept_count_);
    std::copy(frames, frames + 16 * L, kept_frames_.begin());
    has_kept_ = true;
  }

  std::vector<long> near_index_;  // near_'s indices among the contact shapes
  const ZmpCheckSpec& spec_;
  const ShapeSet& shapes_;
  std::vector<long> near_;      // the contact shapes within the tolerance (and round-off) of the ground
  long count_;                  // candidate points per sample: contact shapes x points_per_shape
  std::vector<double> points_;  // their world positions (count_ x 3)
  Points touching_;             // those on the ground (first rows)
  HullWork work_;
  std::vector<int> hull_;
  std::vector<double> vertices_;  // every run's hull vertices
  std::vector<long> start_;       // run r's vertices: rows start_[r] .. start_[r + 1] - 1
  // the kept part (see the class's note): the hull's vertices of the still shapes' touching points, which shapes
  // (kept_shape_, by index among the contact shapes), the frames it was made at; the previous run's frames
  Points kept_points_;
  long kept_count_ = 0;
  bool has_kept_ = false, has_previous_ = false;
  std::vector<double> previous_, kept_frames_;
  std::vector<char> kept_shape_, still_;
};

void check_spec(const ZmpCheckSpec& spec, const ShapeSet& shapes, long n) {
  if (spec.chunk < 1 || spec.points_per_shape < 1) throw InputError("zmp_check: chunk and points_per_shape must be >= 1");
  if (!(std::isfinite(spec.gravity) && spec.gravity > 0.0)) throw InputError("zmp_check: gravity must be finite and > 0");
  for (long s : spec.contact_shapes) check_index("contact", s, shapes);
  for (long s : spec.clearance_shapes) check_index("clearance", s, shapes);
  for (int j : spec.key_joints)
    if (j < 0 || j >= n) throw InputError("zmp_check: key joint " + std::to_string(j) + " is outside the chain");
}

}  // namespace

namespace {

bool same_spec(const ZmpCheckSpec& a, const ZmpCheckSpec& b) {
  return a.contact_shapes == b.contact_shapes && a.points_per_shape == b.points_per_shape &&
         a.clearance_shapes == b.clearance_shapes && a.ground_key == b.ground_key && a.key_joints == b.key_joints &&
         a.shaped_links == b.shaped_links && a.tolerance == b.tolerance && a.chunk == b.chunk;
}

// How zmp_check may take a kept prefix over (see ZmpPrefix): not at all, as it is (made at this origin: to the bit), or
// moved (made at another placement of the base on the ground: the origins' z rows are the same to the bit, so every
// world frame's z row, every height and every contact run is; the momenta, CoM and polygons move with the placement:
// P' = R P, c' = R c + t, L' = R L + t x P' for the turn R about z and the shift t from the prefix's origin to this).
struct Takeover {
  enum Kind { kNone, kSame, kMoved } kind = kNone;
  double c = 1.0, s = 0.0, x = 0.0, y = 0.0;  // the turn's cosine and sine and the shift, when moved
};

Takeover takeover(const ZmpPrefix& prefix, const PathChecker& checker, const ZmpCheckSpec& spec, const double* q,
                  const double* qd, long T) {
  const long m = prefix.size(), n = checker.n_joints();
  if (m < 1 || m > T || prefix.model != &checker.model() || prefix.shapes != &checker.shapes()) return {};
  if (!same_spec(prefix.spec, spec)) return {};
  if (static_cast<long>(prefix.q.size()) != m * n || static_cast<long>(prefix.qd.size()) != m * n) return {};
  const auto bytes = static_cast<std::size_t>(m * n) * sizeof(double);
  if (std::memcmp(prefix.q.data(), q, bytes) != 0 || std::memcmp(prefix.qd.data(), qd, bytes) != 0) return {};
  const Eigen::Matrix4d& from = prefix.origin;
  const Eigen::Matrix4d to = checker.origin().matrix();
  if (from == to) return {Takeover::kSame};
  if (from.row(2) != to.row(2) || from.row(3) != to.row(3) || to.row(3) != Eigen::RowVector4d(0.0, 0.0, 0.0, 1.0))
    return {};
  // D = to * from^-1 keeps z (the z rows are the same): a turn about z and a shift in x, y
  const Eigen::Matrix3d R = to.topLeftCorner<3, 3>() * from.topLeftCorner<3, 3>().transpose();
  const Eigen::Vector3d t = to.topRightCorner<3, 1>() - R * from.topRightCorner<3, 1>();
  const double norm = std::hypot(R(0, 0), R(1, 0));
  if (!(norm > 0.5)) return {};  // (cannot happen for two rotations with the same z row)
  return {Takeover::kMoved, R(0, 0) / norm, R(1, 0) / norm, t.x(), t.y()};
}

// The first m samples' momenta and CoM of a prefix made at another placement, moved to this one (see Takeover).
void move_samples(const Takeover& how, long m, ZmpCheck& out) {
  for (long k = 0; k < m; ++k) {
    double* P = &out.linear[3 * k];
    double* L = &out.angular[3 * k];
    double* c = &out.com[3 * k];
    const double Px = how.c * P[0] - how.s * P[1], Py = how.s * P[0] + how.c * P[1];
    const double Lx = how.c * L[0] - how.s * L[1], Ly = how.s * L[0] + how.c * L[1];
    const double cx = how.c * c[0] - how.s * c[1] + how.x, cy = how.s * c[0] + how.c * c[1] + how.y;
    P[0] = Px;
    P[1] = Py;
    // L about the world origin: + t x P' with t = (x, y, 0)
    L[0] = Lx + how.y * P[2];
    L[1] = Ly - how.x * P[2];
    L[2] = L[2] + how.x * Py - how.y * Px;
    c[0] = cx;
    c[1] = cy;
  }
}

// Where each clearance shape's lowest z is among the contact shapes' (one lowest_z per shape and sample): indices
// into `lowest_of` (the contact shapes, then the clearance shapes that are not contact shapes).
std::vector<long> clearance_slots(const ZmpCheckSpec& spec, std::vector<long>& lowest_of) {
  lowest_of = spec.contact_shapes;
  std::vector<long> slot;
  for (long s : spec.clearance_shapes) {
    const auto at = std::find(lowest_of.begin(), lowest_of.end(), s);
    slot.push_back(static_cast<long>(at - lowest_of.begin()));
    if (at == lowest_of.end()) lowest_of.push_back(s);
  }
  return slot;
}

// Eqs. 33-40 over the whole motion from its per-sample momenta and CoM (out.linear, angular, com) and each sample's
// run (its polygon in `polygons`): the ZMP and its margin.
void zmp_and_margins(const RigidBodyChain& chain, const ZmpCheckSpec& spec, const double* t, long T,
                     const std::vector<long>& run, const SupportRuns& polygons, ZmpCheck& out) {
  std::vector<double> Pdot(static_cast<std::size_t>(3 * T)), Ldot(static_cast<std::size_t>(3 * T));
  time_derivative(t, out.linear.data(), T, 3, Pdot.data());    // Eq. 33's dP/dt
  time_derivative(t, out.angular.data(), T, 3, Ldot.data());   // Eq. 34's dL/dt
  double M = 0.0;
  for (double m : chain.mass) M += m;
  const double Mg = M * spec.gravity;
  out.zmp.resize(static_cast<std::size_t>(2 * T));
  out.margin.resize(static_cast<std::size_t>(T));
  parallel_for(T, kZmpSamplesPerThread, [&](long begin, long end) {
    for (long k = begin; k < end; ++k) {
      const double den = Mg + Pdot[3 * k + 2];
      const double* c = &out.com[3 * k];
      if (!(den > 0.0)) {  // the ground cannot pull: no ZMP, the body would leave the ground
        out.zmp[2 * k] = out.zmp[2 * k + 1] = std::numeric_limits<double>::quiet_NaN();
        out.margin[k] = -kInf;
        continue;
      }
      const Eigen::Vector2d p((Mg * c[0] - Ldot[3 * k + 1]) / den,   // Eq. 39 (p_z = 0)
                              (Mg * c[1] + Ldot[3 * k]) / den);      // Eq. 40
      out.zmp[2 * k] = p.x();
      out.zmp[2 * k + 1] = p.y();
      if (!p.allFinite()) throw InputError("zmp_check: the ZMP is not finite (qd or t out of range)");
      out.margin[k] = polygons.margin(run[k], p);
    }
  });
}

}  // namespace

ZmpCheck zmp_check(const PathChecker& checker, const RigidBodyChain& chain, const ZmpCheckSpec& spec,
                   const double* t, const double* q, const double* qd, long T, const ZmpPrefix* resume, long keep,
                   ZmpPrefix* kept) {
  const ChainModel& model = checker.model();
  const ShapeSet& shapes = checker.shapes();
  const long n = model.n_joints(), L = checker.links();
  if (T < 2) throw InputError("zmp_check: at least two samples are needed");
  for (long k = 1; k < T; ++k)
    if (!(t[k] > t[k - 1])) throw InputError("zmp_check: t must increase strictly");
  check_spec(spec, shapes, n);
  if (keep < 0) throw InputError("zmp_check: keep must be >= 0");
  if (keep > 0 && resume != nullptr) throw InputError("zmp_check: give a prefix to resume from or one to keep, not both");
  ZmpCheck out;
  out.linear.resize(static_cast<std::size_t>(3 * T));
  out.angular.resize(static_cast<std::size_t>(3 * T));
  out.com.resize(static_cast<std::size_t>(3 * T));
  out.clearance.assign(static_cast<std::size_t>(T), kInf);
  SupportRuns polygons(spec, shapes, L);
  std::vector<long> run(static_cast<std::size_t>(T));
  std::vector<double> previous;  // the contact key of the last run
  std::vector<std::vector<double>> run_key;  // each run's contact key (a kept prefix ends with its last)
  long k0 = 0;
  const Takeover how = resume != nullptr ? takeover(*resume, checker, spec, q, qd, T) : Takeover{};
  if (how.kind != Takeover::kNone) {  // its samples (to the bit at its own placement; moved at another)
    k0 = resume->size();
    std::copy(resume->linear.begin(), resume->linear.end(), out.linear.begin());
    std::copy(resume->angular.begin(), resume->angular.end(), out.angular.begin());
    std::copy(resume->com.begin(), resume->com.end(), out.com.begin());
    std::copy(resume->clearance.begin(), resume->clearance.end(), out.clearance.begin());
    std::copy(resume->run.begin(), resume->run.end(), run.begin());
    polygons.restore(resume->vertices, resume->start);
    if (how.kind == Takeover::kMoved) {
      move_samples(how, k0, out);
      polygons.move(how.c, how.s, how.x, how.y);
    }
    previous = resume->last_key;
    run_key.resize(static_cast<std::size_t>(polygons.runs()));
    run_key.back() = previous;
    out.resumed = k0;
  }
  // one lowest_z per shape and sample: the contact shapes, then the clearance shapes that are not among them
  std::vector<long> lowest_of;
  const std::vector<long> slot = clearance_slots(spec, lowest_of);
  const long U = static_cast<long>(lowest_of.size());
  const long K = spec.ground_key ? static_cast<long>(chain.joint_child.size()) + 1
                                 : static_cast<long>(spec.key_joints.size());  // contact_key's length
  const std::vector<int>& child = chain.joint_child;
  const auto nbytes = static_cast<std::size_t>(n) * sizeof(double);
  // the sample repeats the one before (a hold: ~500 samples a target): its values are that one's, to the bit
  const auto repeats = [&](long k) {
    return k > 0 && k % spec.chunk != 0 && std::memcmp(q + k * n, q + (k - 1) * n, nbytes) == 0 &&
           std::memcmp(qd + k * n, qd + (k - 1) * n, nbytes) == 0;
  };
  // In blocks of kZmpBlock samples (bounded buffers): 1. each sample on its own, split over the core's threads
  // (frames, momenta, CoM, lowest points, clearance, contact key); 2. in order, the repeats and the contact runs (a
  // new polygon where the key changes, from the sample's frames again).
  std::vector<double> lows(static_cast<std::size_t>(kZmpBlock * U)), keys(static_cast<std::size_t>(kZmpBlock * K));
  std::vector<double> frames(static_cast<std::size_t>(16 * L));
  Frames work;
  for (long b0 = k0; b0 < T; b0 += kZmpBlock) {
    const long b1 = std::min(T, b0 + kZmpBlock);
    parallel_for(b1 - b0, kZmpSamplesPerThread, [&](long begin, long end) {
      std::vector<double> own_frames(static_cast<std::size_t>(16 * L)), key;
      Frames own_work;
      for (long k = b0 + begin; k < b0 + end; ++k) {
        if (repeats(k)) continue;
        const Eigen::Map<const Eigen::VectorXd> qk(q + k * n, n);
        model.check_configuration(qk);
        checker.world_frames(qk, own_frames.data(), own_work);
        momenta(chain, own_frames.data(), qd + k * n, 1, L, &out.linear[3 * k], &out.angular[3 * k], &out.com[3 * k]);
        double* low = &lows[static_cast<std::size_t>((k - b0) * U)];
        lowest_z(own_frames.data(), 1, L, shapes, lowest_of.data(), U, low);
        for (long c : slot) out.clearance[k] = std::min(out.clearance[k], low[static_cast<std::size_t>(c)]);
        contact_key(spec, child, shapes, low, q + k * n, key);
        if (static_cast<long>(key.size()) != K) throw std::logic_error("zmp_check: a contact key of another length");
        std::copy(key.begin(), key.end(), keys.begin() + (k - b0) * K);
      }
    });
    for (long k = b0; k < b1; ++k) {
      if (repeats(k)) {
        for (int c = 0; c < 3; ++c) {
          out.linear[3 * k + c] = out.linear[3 * (k - 1) + c];
          out.angular[3 * k + c] = out.angular[3 * (k - 1) + c];
          out.com[3 * k + c] = out.com[3 * (k - 1) + c];
        }
        out.clearance[k] = out.clearance[k - 1];
        run[k] = run[k - 1];
        continue;
      }
      const auto key = keys.begin() + (k - b0) * K;
      if (k % spec.chunk == 0 || previous.size() != static_cast<std::size_t>(K) ||
          !std::equal(key, key + K, previous.begin())) {
        checker.world_frames(Eigen::Map<const Eigen::VectorXd>(q + k * n, n), frames.data(), work);
        polygons.add(frames.data(), L, &lows[static_cast<std::size_t>((k - b0) * U)]);
        previous.assign(key, key + K);
        if (keep > 0 && k < keep) run_key.push_back(previous);
      }
      run[k] = polygons.runs() - 1;
    }
  }
  if (keep > 0 && kept != nullptr) {
    const long m = std::min(keep, T);
    const auto m3 = static_cast<std::size_t>(3 * m), mn = static_cast<std::size_t>(m * n);
    ZmpPrefix& p = *kept;
    p.model = &model;
    p.shapes = &shapes;
    p.origin = checker.origin().matrix();
    p.spec = spec;
    p.q.assign(q, q + mn);
    p.qd.assign(qd, qd + mn);
    p.linear.assign(out.linear.begin(), out.linear.begin() + m3);
    p.angular.assign(out.angular.begin(), out.angular.begin() + m3);
    p.com.assign(out.com.begin(), out.com.begin() + m3);
    p.clearance.assign(out.clearance.begin(), out.clearance.begin() + m);
    p.run.assign(run.begin(), run.begin() + m);
    polygons.keep(run[m - 1] + 1, p.vertices, p.start);
    p.last_key = run_key[static_cast<std::size_t>(run[m - 1])];
  }
  zmp_and_margins(chain, spec, t, T, run, polygons, out);
  return out;
}

RigidBodyChain chain_dynamics(const ChainModel& model) {
  RigidBodyChain chain;
  for (const auto& s : model.segments()) {
    chain.joint_child.push_back(model.link_index(s.link));
    chain.axis.push_back(s.axis);
  }
  for (const auto& link : model.links()) {
    chain.mass.push_back(link.mass);
    chain.com.push_back(link.com);
    chain.inertia.push_back(link.inertia);
  }
  return chain;
}

}  // namespace snakehead
