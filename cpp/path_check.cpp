#include "snakehead/path_check.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "snakehead/kinematics.hpp"

namespace snakehead {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
using Row4 = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>;

using ItemKind = PathChecker::ItemKind;

// Intervals are not split deeper than this many times (a floor_step of 0 would otherwise recurse without end).
constexpr int kMaxDepth = 40;

}  // namespace

void check_shape_index(const char* what, long index, const ShapeSet& set) {
  if (index < 0 || index >= set.size())
    throw InputError(std::string("PathChecker: ") + what + " shape index " + std::to_string(index) +
                     " is outside the set of " + std::to_string(set.size()) + " shapes");
}

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
  for (const auto& s : model_.segments())
    if (s.prismatic) throw InputError("PathChecker: prismatic joints are not supported (the motion bound needs revolute joints)");
  if (shapes_.max_frame() >= static_cast<int>(model_.links().size()))
    throw InputError("PathChecker: a shape is attached to a frame the chain does not have");
  if (obstacles_ != nullptr && obstacles_->max_frame() > 0)
    throw InputError("PathChecker: obstacle shapes must all be on frame 0 (the world)");
  measure_reach();
  list_items();
}

void PathChecker::measure_reach() {
  const auto& segs = model_.segments();
  const int n = model_.n_joints();
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
}

void PathChecker::list_items() {
  for (long s : spec_.ground_shapes) {
    check_shape_index("ground", s, shapes_);
    items_.push_back({ItemKind::Ground, s, -1});
  }
  for (const auto& p : spec_.self_pairs) {
    check_shape_index("self pair", p[0], shapes_);
    check_shape_index("self pair", p[1], shapes_);
    // the earlier shape first: the pair's bound counts the joints between them
    const bool swap = joint_of_shape_[p[0]] > joint_of_shape_[p[1]];
    items_.push_back({ItemKind::Self, swap ? p[1] : p[0], swap ? p[0] : p[1]});
  }
  for (const auto& p : spec_.obstacle_pairs) {
    if (obstacles_ == nullptr) throw InputError("PathChecker: obstacle pairs given without obstacles");
    check_shape_index("obstacle pair", p[0], shapes_);
    check_shape_index("obstacle pair", p[1], *obstacles_);
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
// The proof over a path (check_path) or a sampled motion (check_motion).

// One proof: the samples it evaluates, the motion bound of each interval between two of them, the cone test, and
// the verdict so far.
class PathProof {
 public:
  PathProof(const PathChecker& c, const PathOptions& o) : c_(c), o_(o) {}

  // check_path over K waypoints (K x n): each straight segment between two, first sampled at most first_step apart.
  PathVerdict run(const double* waypoints, long K);
  // check_motion over T samples (T x n) joined by straight segments.
  MotionVerdict run_motion(const double* qs, long T);
  // The configuration q: its frames and joints, its shapes' bounding-sphere centres and each item's cheap bound.
  Sample evaluate(const Eigen::VectorXd& q);
  // The motion bounds of the interval a -> b (see the header): B_S and Z_S per robot shape, and each self pair's
  // bound (pair_), the sum over the joints between the pair's links only. dq[j]: how far joint j travels between a
  // and b (|b.q - a.q| along a straight segment, the total variation along a motion).
  void bounds(const Sample& a, const Sample& b, const Eigen::VectorXd& dq, std::vector<double>& B,
              std::vector<double>& Z);

 private:
  enum class Status { Clear, Split, Violated };

  // Items at a sample.
  Eigen::Isometry3d pose(const Sample& s, long shape) const;
  double cheap(const Sample& s, const PathChecker::Item& it, unsigned char& exact);
  double exact(Sample& s, std::size_t i);
  void note(const PathChecker::Item& it, double d);
  bool passes(const PathChecker::Item& it, double value) const;
  void single(Sample& s);
  double obstacle_at(Sample& s);

  // Intervals.
  void check_steps(const char* who) const;
  void shape_bounds(const Sample& a, const Sample& b, const Eigen::VectorXd& dq, std::vector<double>& B,
                    std::vector<double>& Z);
  void pair_bounds(const Eigen::VectorXd& dq);
  Status interval(Sample& a, Sample& b, const Eigen::VectorXd& dq);
  bool prove(Sample& a, Sample& b, int depth);
  bool segment(Sample& a, Sample& b);

  // A sampled motion.
  void start_motion(const double* qs, long T);
  long next_evaluated(long a, long T) const;
  Eigen::Map<const Eigen::VectorXd> row(long k) const;
  void motion(long a, long b, Sample& sa, Sample& sb);
  MotionVerdict motion_verdict();

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

PathVerdict PathProof::run(const double* waypoints, long K) {
  const long n = c_.model_.n_joints();
  if (K < 1) throw InputError("check_path: at least one waypoint is needed");
  check_steps("check_path");
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

Sample PathProof::evaluate(const Eigen::VectorXd& q) {
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

// ---- items at a sample

Eigen::Isometry3d PathProof::pose(const Sample& s, long shape) const {
  Eigen::Isometry3d frame;
  frame.matrix() = Eigen::Map<const Row4>(s.frames.data() + 16 * c_.shapes_.shape(static_cast<int>(shape)).frame);
  return frame * c_.shapes_.shape(static_cast<int>(shape)).origin;
}

// The item's lower bound from the bounding spheres (exact for the ground: it is a closed form).
double PathProof::cheap(const Sample& s, const PathChecker::Item& it, unsigned char& exact) {
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

// Item i's exact value at s (computed once: its signed distance).
double PathProof::exact(Sample& s, std::size_t i) {
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

// An evaluated value into the verdict's smallest of its kind.
void PathProof::note(const PathChecker::Item& it, double d) {
  double& m = it.kind == ItemKind::Ground ? v_.ground : it.kind == ItemKind::Self ? v_.self : v_.obstacle;
  m = std::min(m, d);
}

bool PathProof::passes(const PathChecker::Item& it, double value) const {
  return it.kind == ItemKind::Ground ? value >= c_.spec_.ground_floor : value > 0.0;
}

// A single configuration: clear when every item passes exactly.
void PathProof::single(Sample& s) {
  for (std::size_t i = 0; i < c_.items_.size(); ++i)
    if (!passes(c_.items_[i], s.lower[i]) && !passes(c_.items_[i], exact(s, i))) ++v_.violations;
}

// The smallest obstacle value known at an evaluated sample (exact where its cheap bound is below the cutoff, as
// PathChecker::sample reports it).
double PathProof::obstacle_at(Sample& s) {
  double m = kInf;
  for (std::size_t i = 0; i < c_.items_.size(); ++i) {
    if (c_.items_[i].kind != ItemKind::Obstacle) continue;
    m = std::min(m, s.lower[i] < c_.spec_.obstacle_cutoff ? exact(s, i) : s.lower[i]);
  }
  return m;
}

// ---- intervals

void PathProof::check_steps(const char* who) const {
  if (!(o_.first_step > 0.0) || !(o_.floor_step >= 0.0) || !std::isfinite(o_.first_step))
    throw InputError(std::string(who) + ": first_step must be finite and > 0, floor_step >= 0");
}

void PathProof::bounds(const Sample& a, const Sample& b, const Eigen::VectorXd& dq, std::vector<double>& B,
                       std::vector<double>& Z) {
  shape_bounds(a, b, dq, B, Z);
  pair_bounds(dq);
}

// B_S and Z_S per robot shape; radius_ keeps r_{j,S} + rho for pair_bounds.
void PathProof::shape_bounds(const Sample& a, const Sample& b, const Eigen::VectorXd& dq, std::vector<double>& B,
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
}

// Each self pair's bound into pair_: in the earlier link's frame only the joints after it move the later shape, each
// about the same axis distance (frame-invariant) but with the relative term counting the joints after j only:
// r_{j,S2} holds.
void PathProof::pair_bounds(const Eigen::VectorXd& dq) {
  const int n = c_.model_.n_joints();
  pair_.assign(c_.items_.size(), 0.0);
  for (std::size_t i = 0; i < c_.items_.size(); ++i) {
    const PathChecker::Item& it = c_.items_[i];
    if (it.kind != ItemKind::Self) continue;
    double sum = 0.0;
    for (int j = c_.joint_of_shape_[it.b]; j > c_.joint_of_shape_[it.a]; --j)
      sum += dq[j] * radius_[static_cast<std::size_t>(it.b * n + j)];
    pair_[i] = sum;
  }
}

// The interval a -> b along which joint j travels at most dq[j], by the cone bound; obstacle_ is left at the smallest
// lower bound of the obstacle distances over it (the cone bound, or the value at a violated end).
PathProof::Status PathProof::interval(Sample& a, Sample& b, const Eigen::VectorXd& dq) {
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

// Proves [a, b]; splits it (down to the floor) where the bound is too loose.
bool PathProof::prove(Sample& a, Sample& b, int depth) {
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
bool PathProof::segment(Sample& a, Sample& b) {
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

// ---- a sampled motion

MotionVerdict PathProof::run_motion(const double* qs, long T) {
  start_motion(qs, T);
  Sample prev = evaluate(row(0));
  if (T == 1) single(prev);
  lower_[0] = obstacle_at(prev);
  for (long a = 0; a + 1 < T;) {
    const long b = next_evaluated(a, T);
    Sample next = evaluate(row(b));
    motion(a, b, prev, next);
    prev = std::move(next);
    a = b;
  }
  lower_[static_cast<std::size_t>(T - 1)] = std::min(lower_[static_cast<std::size_t>(T - 1)], obstacle_at(prev));
  return motion_verdict();
}

// Checks the motion's arguments; travel_(k, j): joint j's total variation from sample 0 to sample k along the
// straight segments.
void PathProof::start_motion(const double* qs, long T) {
  const long n = c_.model_.n_joints();
  if (T < 1) throw InputError("check_motion: at least one sample is needed");
  check_steps("check_motion");
  qs_ = qs;
  complete_ = true;
  travel_.resize(T, n);
  travel_.row(0).setZero();
  for (long k = 1; k < T; ++k)
    for (long j = 0; j < n; ++j) travel_(k, j) = travel_(k - 1, j) + std::abs(qs[k * n + j] - qs[(k - 1) * n + j]);
  lower_.assign(static_cast<std::size_t>(T), kInf);
}

// The next sample to evaluate after a: the last before some joint has travelled more than first_step since a
// (a + 1 at least).
long PathProof::next_evaluated(long a, long T) const {
  long b = a + 1;
  while (b + 1 < T && (travel_.row(b + 1) - travel_.row(a)).maxCoeff() <= o_.first_step) ++b;
  return b;
}

Eigen::Map<const Eigen::VectorXd> PathProof::row(long k) const {
  const long n = c_.model_.n_joints();
  return Eigen::Map<const Eigen::VectorXd>(qs_ + k * n, n);
}

// Samples a..b (evaluated: sa, sb) of the motion: proven with the joints' total variation, else halved by sample
// index; two consecutive samples are proven along their straight segment (prove). Writes lower_[a..b-1].
void PathProof::motion(long a, long b, Sample& sa, Sample& sb) {
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

MotionVerdict PathProof::motion_verdict() {
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

}  // namespace snakehead
