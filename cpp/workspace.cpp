// The workspace's parts beside the sweep (workspace_sweep.cpp): options, the grid, the hull, approach frames, the
// point cloud, the reach bounds, the TRAC-IK pose solver, and maps merged and saved.
#include "snakehead/workspace.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>

#include "snakehead/kinematics.hpp"
#include "snakehead/limits.hpp"
#include "snakehead/npz.hpp"
#include "snakehead/random_numbers.hpp"
#include "snakehead/trac_ik.hpp"
#include "qhull_run.hpp"

namespace snakehead {
namespace {

constexpr std::uint64_t kCloudSalt = 0xC10D;  // the point cloud's stream

class TracIKPoseSolver : public PoseSolver {
 public:
  TracIKPoseSolver(std::shared_ptr<const TracIK> ik, const WorkspaceOptions& o) : ik_(std::move(ik)) {
    opts_.timeout = o.timeout;
    opts_.epsilon = o.epsilon;
    opts_.solve_type = SolveType::Speed;
    opts_.bounds.setZero();
    free_ = opts_;
    free_.bounds[o.approach == ApproachAxis::X ? 3 : 5] = std::numeric_limits<double>::infinity();
    if (o.free_roll) opts_ = free_;
  }
  bool solve(const Eigen::Isometry3d& target, const Eigen::VectorXd& q_init, std::uint64_t call_seed, double budget,
             Eigen::VectorXd& q_out) override {
    return run(opts_, target, q_init, call_seed, budget, q_out);
  }
  bool solve_free_roll(const Eigen::Isometry3d& target, const Eigen::VectorXd& q_init, std::uint64_t call_seed,
                       double budget, Eigen::VectorXd& q_out) override {
    return run(free_, target, q_init, call_seed, budget, q_out);
  }

 private:
  bool run(const TracIKOptions& base, const Eigen::Isometry3d& target, const Eigen::VectorXd& q_init,
           std::uint64_t call_seed, double budget, Eigen::VectorXd& q_out) {
    call_ = base;
    call_.timeout = base.timeout * budget;
    call_.seed = call_seed;  // seeded TRAC-IK: a pure function of its inputs, run in this thread
    IKResult r = ik_->solve_ex(target, q_init, call_);
    if (r.found) q_out = r.q;
    return r.found;
  }
  std::shared_ptr<const TracIK> ik_;
  TracIKOptions opts_, free_, call_;
};

}  // namespace

ReachBound::ReachBound(const ChainModel& model, const WorkspaceOptions& o)
    : reach_(model.reach()), approach_(o.approach) {
  const auto& segs = model.segments();
  revolute_ = std::none_of(segs.begin(), segs.end(), [](const SegmentGeometry& s) { return s.prismatic; });
  first_joint_ = segs.front().pre.translation();
  // Distances between consecutive joint origins do not change with a revolute joint's angle (each
  // joint turns about an axis through its own origin).
  arm_ = 0.0;
  for (std::size_t k = 0; k + 1 < segs.size(); ++k) arm_ += (segs[k].post * segs[k + 1].pre).translation().norm();
  // The last joint's origin in the tip frame: T_tip = J * Motion(q) * post, and Motion fixes J's origin.
  wrist_in_tip_ = segs.back().post.inverse().translation();
  const Eigen::Vector3d a = o.approach == ApproachAxis::X ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitZ();
  wrist_along_ = wrist_in_tip_.dot(a);
  wrist_radius_ = (wrist_in_tip_ - wrist_along_ * a).norm();
  slack_ = 1e-6 + 2.0 * o.epsilon;  // never reject a pose the IK would accept within its tolerance

  // The second-last joint's origin (the "elbow") in the tip frame turns on an arc about the last
  // joint's axis as the last joint moves within its limits; sample the arc. A point of the arc lies
  // within rho * step / 2 of a sample (rho: the arc's radius), which the test adds as slack.
  const int n = static_cast<int>(segs.size());
  if (!revolute_ || n < 2) return;
  const Eigen::Isometry3d link = segs[n - 2].post * segs[n - 1].pre;  // joint n-2 frame -> joint n-1 frame
  const Eigen::Vector3d elbow = link.inverse().translation();         // elbow in the last joint's frame
  arm2_ = arm_ - link.translation().norm();
  const Eigen::Vector3d axis = segs[n - 1].axis;
  const double rho = (elbow - elbow.dot(axis) * axis).norm();
  const SamplingRange range(model);  // the last joint's range
  const double lo = range.lo[n - 1], hi = range.hi[n - 1];
  const int samples = 64;
  const double step = (hi - lo) / (samples - 1);
  const Eigen::Isometry3d post_inv = segs[n - 1].post.inverse();
  for (int k = 0; k < samples; ++k) {
    const double q = lo + step * k;
    elbow_in_tip_.push_back(post_inv * (Eigen::AngleAxisd(-q, axis) * elbow));
  }
  elbow_slack_ = rho * step / 2.0;
  // Free roll: the elbow points also turn about the approach axis through the tip; sampling the roll
  // in `roll_samples_` steps adds (distance from the axis) * roll_step / 2.
  double far = 0.0;
  for (const auto& e : elbow_in_tip_) far = std::max(far, (e - e.dot(a) * a).norm());
  roll_step_ = 2.0 * M_PI / kRollSamples;
  roll_slack_ = far * roll_step_ / 2.0;
  approach_local_ = a;
}

bool ReachBound::elbow_possible(const Eigen::Isometry3d& target, double extra_slack) const {
  if (elbow_in_tip_.empty()) return true;
  const double limit = arm2_ + slack_ + elbow_slack_ + extra_slack;
  const double limit2 = limit * limit;
  for (const auto& e : elbow_in_tip_)
    if (((target * e) - first_joint_).squaredNorm() <= limit2) return true;
  return false;
}

bool ReachBound::possible(const Eigen::Isometry3d& target) const {
  if (target.translation().norm() > reach_ + slack_) return false;
  if (!revolute_) return true;
  if (((target * wrist_in_tip_) - first_joint_).norm() > arm_ + slack_) return false;
  return elbow_possible(target, 0.0);
}

bool ReachBound::possible_any_roll(const Eigen::Vector3d& p, const Eigen::Vector3d& a) const {
  if (p.norm() > reach_ + slack_) return false;
  if (!revolute_) return true;
  // With the roll about the approach axis a free, the wrist point runs on a circle about a: take
  // the point of the circle closest to the first joint.
  const Eigen::Vector3d m = p + wrist_along_ * a;
  const Eigen::Vector3d d = first_joint_ - m;
  const double h = d.dot(a);
  const double radial = (d - h * a).norm();
  if (std::hypot(h, radial - wrist_radius_) > arm_ + slack_) return false;
  if (elbow_in_tip_.empty()) return true;
  const Eigen::Isometry3d frame = approach_frame(p, a, 0.0, approach_);
  for (int r = 0; r < kRollSamples; ++r) {
    Eigen::Isometry3d rolled = frame;
    rolled.linear() = frame.linear() * Eigen::AngleAxisd(roll_step_ * r, approach_local_).toRotationMatrix();
    if (elbow_possible(rolled, roll_slack_)) return true;
  }
  return false;
}

ApproachAxis parse_approach_axis(const std::string& s) {
  if (s == "x" || s == "X") return ApproachAxis::X;
  if (s == "z" || s == "Z") return ApproachAxis::Z;
  throw InputError("approach axis must be 'x' or 'z', got '" + s + "'");
}

const char* approach_axis_name(ApproachAxis a) { return a == ApproachAxis::X ? "x" : "z"; }

HullKind parse_hull_kind(const std::string& s) {
  if (s == "boundary") return HullKind::Boundary;
  if (s == "convex") return HullKind::Convex;
  throw InputError("hull must be 'boundary' or 'convex', got '" + s + "'");
}

const char* hull_kind_name(HullKind h) { return h == HullKind::Boundary ? "boundary" : "convex"; }

void WorkspaceOptions::validate() const {
  // Upper limits (limits.hpp) keep every buffer a sweep allocates, and the clock deadline of each IK call,
  // within reach: a number beyond one is a mistake, reported before any work.
  auto count_in = [](const char* field, long long value, long long least, long long most, const char* hint = "") {
    if (value < least || value > most)
      throw InputError(std::string(field) + " must be between " + std::to_string(least) + " and " +
                       std::to_string(most) + hint + ", got " + std::to_string(value));
  };
  if (!(std::isfinite(voxel_size) && voxel_size > 0))
    throw InputError("voxel size must be a positive number of metres, got " + number_text(voxel_size));
  count_in("directions", directions, 1, limits::kMaxDirections);
  if (!free_roll) {
    count_in("rolls", rolls, 1, limits::kMaxRolls, " (or use free roll)");
    count_in("directions x rolls (frames per voxel)", static_cast<long long>(directions) * rolls, 1,
             limits::kMaxFramesPerVoxel);
  }
  check_timeout(timeout, "timeout");
  if (!(std::isfinite(epsilon) && epsilon > 0))
    throw InputError("epsilon must be positive, got " + number_text(epsilon));
  count_in("cloud_samples", cloud_samples, 100, limits::kMaxCloudSamples, " (the hull needs a cloud)");
  if (!(shrink >= 0.0 && shrink <= 1.0))
    throw InputError("shrink (the boundary's shrink factor) must be within [0, 1], got " + number_text(shrink));
  count_in("threads", threads, 0, limits::kMaxThreads, " (0 = all cores)");
  if (shard_count < 1 || shard_index < 0 || shard_index >= shard_count)
    throw InputError("shard must be i/N with 0 <= i < N, got " + std::to_string(shard_index) + "/" +
                     std::to_string(shard_count));
}

VoxelGrid VoxelGrid::around(const Eigen::Vector3d& centre, double side, double voxel) {
  if (!(std::isfinite(voxel) && voxel > 0)) throw InputError("voxel size must be positive");
  if (!(std::isfinite(side) && side > 0)) throw InputError("grid side must be positive");
  const double cells = std::ceil(side / voxel - 1e-9);
  if (!(cells <= limits::kMaxVoxelsPerAxis))
    throw InputError("voxel size " + number_text(voxel) + " m is too small for the grid of side " + number_text(side) +
                     " m: " + number_text(cells) + " voxels per axis, at most " +
                     std::to_string(limits::kMaxVoxelsPerAxis) + " (voxel size >= " +
                     number_text(side / limits::kMaxVoxelsPerAxis) + " m)");
  VoxelGrid g;
  g.n = std::max(1, static_cast<int>(cells));
  g.voxel = voxel;
  g.origin = centre - Eigen::Vector3d::Constant(0.5 * g.n * voxel);
  return g;
}

Eigen::Vector3d VoxelGrid::centre_of(std::int64_t k) const {
  const std::int64_t l = k % n, j = (k / n) % n, i = k / (static_cast<std::int64_t>(n) * n);
  return origin + voxel * Eigen::Vector3d(i + 0.5, j + 0.5, l + 0.5);
}

ConvexHull ConvexHull::of(const std::vector<Eigen::Vector3d>& points) {
  if (points.size() < 4) throw InputError("a convex hull in 3-D needs at least 4 points");
  QhullRun run(points, "qhull Qt");  // Qt: triangulated output (simplicial facets, planes as computed)
  qhT* qh = run.qh;
  ConvexHull hull;
  if (run.ok()) {
    std::vector<Eigen::Vector3d> normals;
    std::vector<double> offsets;
    facetT* facet;
    FORALLfacets {
      normals.emplace_back(facet->normal[0], facet->normal[1], facet->normal[2]);
      offsets.push_back(facet->offset);
    }
    hull.normals.resize(static_cast<Eigen::Index>(normals.size()), 3);
    hull.offsets.resize(static_cast<Eigen::Index>(offsets.size()));
    for (std::size_t k = 0; k < normals.size(); ++k) {
      hull.normals.row(static_cast<Eigen::Index>(k)) = normals[k].transpose();
      hull.offsets[static_cast<Eigen::Index>(k)] = offsets[k];
    }
    hull.n_vertices = qh->num_vertices;
    qh_getarea(qh, qh->facet_list);
    hull.volume = qh->totvol;
  }
  if (!run.ok())
    throw InputError("the tip's point cloud spans no volume, so it has no convex hull (qhull: " + run.error() + ")");
  return hull;
}

bool ConvexHull::contains(const Eigen::Vector3d& p, double tolerance) const {
  if (offsets.size() == 0) return false;
  return ((normals * p + offsets).array() <= tolerance).all();
}

std::vector<Eigen::Vector3d> fibonacci_directions(int n) {
  if (n < 1 || n > limits::kMaxDirections)
    throw InputError("directions must be between 1 and " + std::to_string(limits::kMaxDirections) + ", got " +
                     std::to_string(n));
  // Points at equal-area heights z_k = 1 - (2k + 1) / n, turned by the golden angle each step.
  const double golden_angle = M_PI * (3.0 - std::sqrt(5.0));
  std::vector<Eigen::Vector3d> d(n);
  for (int k = 0; k < n; ++k) {
    const double z = 1.0 - (2.0 * k + 1.0) / n;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = golden_angle * k;
    d[k] = Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z);
  }
  return d;
}

Eigen::Isometry3d approach_frame(const Eigen::Vector3d& point, const Eigen::Vector3d& direction, double roll,
                                 ApproachAxis axis) {
  const double norm = direction.norm();
  if (!(std::isfinite(norm) && norm > 0)) throw InputError("approach direction must be a finite non-zero vector");
  if (!point.allFinite() || !std::isfinite(roll)) throw InputError("approach frame point and roll must be finite");
  const Eigen::Vector3d a = direction / norm;
  // Roll 0: the first tangent axis is the world axis least aligned with a, made perpendicular to it.
  Eigen::Index least;
  a.cwiseAbs().minCoeff(&least);
  Eigen::Vector3d u = Eigen::Vector3d::Unit(least) - a[least] * a;
  u.normalize();
  const Eigen::Vector3d v = a.cross(u);
  const Eigen::Vector3d t = std::cos(roll) * u + std::sin(roll) * v;
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  if (axis == ApproachAxis::X) {
    f.linear().col(0) = a;  // x = a, y = t, z = x cross y
    f.linear().col(1) = t;
    f.linear().col(2) = a.cross(t);
  } else {
    f.linear().col(2) = a;  // z = a, x = t, y = z cross x
    f.linear().col(0) = t;
    f.linear().col(1) = a.cross(t);
  }
  f.translation() = point;
  return f;
}

std::vector<Eigen::Vector3d> sample_tip_positions(const ChainModel& model, int samples, std::uint64_t seed) {
  if (samples < 1 || samples > limits::kMaxCloudSamples)
    throw InputError("samples must be between 1 and " + std::to_string(limits::kMaxCloudSamples) + ", got " +
                     std::to_string(samples));
  std::mt19937_64 rng(stream_seed(seed, kCloudSalt, 0));
  const SamplingRange range(model);
  std::vector<Eigen::Vector3d> pts(samples);
  Eigen::VectorXd q;
  for (int k = 0; k < samples; ++k) {
    range.draw(rng, q);
    pts[k] = forward_kinematics(model, q).translation();
  }
  return pts;
}

PoseSolverFactory trac_ik_solver_factory() {
  return [](const ChainModel& model, const WorkspaceOptions& o) -> std::unique_ptr<PoseSolver> {
    TracIKOptions t;
    t.timeout = o.timeout;
    t.epsilon = o.epsilon;
    auto ik = std::make_shared<const TracIK>(model, t);
    return std::make_unique<TracIKPoseSolver>(std::move(ik), o);
  };
}

Eigen::VectorXd ReachabilityMap::indices() const {
  Eigen::VectorXd d(static_cast<Eigen::Index>(solved.size()));
  for (std::size_t k = 0; k < solved.size(); ++k)
    d[static_cast<Eigen::Index>(k)] = tried > 0 ? 100.0 * solved[k] / tried : 0.0;
  return d;
}

namespace {
bool same_options(const WorkspaceOptions& a, const WorkspaceOptions& b) {
  return a.voxel_size == b.voxel_size && a.directions == b.directions &&
         (a.free_roll ? b.free_roll : !b.free_roll && a.rolls == b.rolls && a.any_roll == b.any_roll) && a.approach == b.approach &&
         a.timeout == b.timeout && a.epsilon == b.epsilon &&
         a.cloud_samples == b.cloud_samples && a.seed == b.seed && a.shard_count == b.shard_count &&
         a.hull == b.hull && a.map_shrink() == b.map_shrink();
}
}  // namespace

ReachabilityMap merge_shards(const std::vector<ReachabilityMap>& shards) {
  if (shards.empty()) throw InputError("merge needs at least one shard");
  const ReachabilityMap& first = shards.front();
  const int n = first.options.shard_count;
  if (static_cast<int>(shards.size()) != n)
    throw InputError("the map has " + std::to_string(n) + " shards; got " + std::to_string(shards.size()));
  std::vector<bool> seen(n, false);
  for (const auto& s : shards) {
    if (!same_options(s.options, first.options) || s.chain_hash != first.chain_hash ||
        s.hull_voxels != first.hull_voxels || s.grid.n != first.grid.n || s.grid.voxel != first.grid.voxel)
      throw InputError("shards of different maps (parameters, chain or grid differ) cannot be merged");
    const int i = s.options.shard_index;
    if (seen[i]) throw InputError("shard " + std::to_string(i) + "/" + std::to_string(n) + " given twice");
    seen[i] = true;
  }
  // Rows of the merged map by grid index: (shard, row in that shard).
  std::map<std::int64_t, std::pair<std::size_t, std::size_t>> voxels;
  const bool with_bits = std::all_of(shards.begin(), shards.end(), [](const ReachabilityMap& s) {
    return s.reached.size() == s.voxel_ids.size() * reached_bytes_per_voxel(s.tried);
  });
  ReachabilityMap out = first;
  out.ik_calls = out.cheap_exits = 0;
  out.seconds = 0.0;
  for (std::size_t i = 0; i < shards.size(); ++i) {
    const ReachabilityMap& s = shards[i];
    for (std::size_t v = 0; v < s.voxel_ids.size(); ++v)
      if (!voxels.emplace(s.voxel_ids[v], std::make_pair(i, v)).second)
        throw InputError("voxel " + std::to_string(s.voxel_ids[v]) + " appears in two shards");
    out.ik_calls += s.ik_calls;
    out.cheap_exits += s.cheap_exits;
    out.seconds += s.seconds;
  }
  if (static_cast<std::int64_t>(voxels.size()) != first.hull_voxels)
    throw InputError("the shards hold " + std::to_string(voxels.size()) + " voxels; the map has " +
                     std::to_string(first.hull_voxels));
  out.options.shard_index = 0;
  out.options.shard_count = 1;
  out.voxel_ids.clear();
  out.solved.clear();
  out.reached.clear();
  out.base_joints.clear();  // (shards of whole-body maps are not merged here)
  out.base_placements.clear();
  const int bytes = reached_bytes_per_voxel(first.tried);
  out.centres.resize(static_cast<Eigen::Index>(voxels.size()), 3);
  Eigen::Index row = 0;
  for (const auto& [k, where] : voxels) {
    const ReachabilityMap& s = shards[where.first];
    const std::size_t v = where.second;
    out.voxel_ids.push_back(k);
    out.centres.row(row++) = s.centres.row(static_cast<Eigen::Index>(v));
    out.solved.push_back(s.solved[v]);
    if (with_bits) out.reached.insert(out.reached.end(), s.reached.begin() + v * bytes, s.reached.begin() + (v + 1) * bytes);
  }
  return out;
}

void save_npz(const ReachabilityMap& map, const std::string& path, const std::string& command) {
  const auto m = static_cast<std::int64_t>(map.voxel_ids.size());
  const int bytes = reached_bytes_per_voxel(map.tried);
  if (map.tried < 1) throw InputError("a map tries at least one pose per voxel");
  if (map.centres.rows() != m || static_cast<std::int64_t>(map.solved.size()) != m)
    throw InputError("a map needs one centre and one solved count per voxel id");
  if (!map.reached.empty() && static_cast<std::int64_t>(map.reached.size()) != m * bytes)
    throw InputError("a map's per-direction results need " + std::to_string(bytes) + " bytes per voxel");
  if (!std::is_sorted(map.voxel_ids.begin(), map.voxel_ids.end()))
    throw InputError("a map's voxel ids must be ascending");
  if (map.kind != kMapKindHead && map.kind != kMapKindWholeBody)
    throw InputError("a map's kind is 'head' or 'whole-body', got '" + map.kind + "'");
  const std::int64_t poses = m * map.tried;
  if (!map.base_joints.empty() &&
      (map.base_joint_count < 1 || static_cast<std::int64_t>(map.base_joints.size()) != poses * map.base_joint_count))
    throw InputError("a map's base joints need base_joint_count (>= 1) values per voxel and pose");
  if (!map.base_placements.empty() && static_cast<std::int64_t>(map.base_placements.size()) != poses * 3)
    throw InputError("a map's base placements need 3 values (x, y, yaw) per voxel and pose");
  NpzWriter w;
  w.add_string("format", kMapFormat);
  std::vector<double> centres(map.centres.data(), map.centres.data() + map.centres.size());
  w.add_f64("centers", centres, {m, 3});
  const Eigen::VectorXd d = map.indices();
  w.add_f64("indices", std::vector<double>(d.data(), d.data() + d.size()), {m});
  w.add_i32("solved", map.solved, {m});
  w.add_i64("voxel_ids", map.voxel_ids, {m});
  if (!map.reached.empty()) w.add_u8("reached", map.reached, {m, bytes});
  w.add_string("map_kind", map.kind);
  if (!map.base_joints.empty()) w.add_f64("base_joints", map.base_joints, {m, map.tried, map.base_joint_count});
  if (!map.base_placements.empty()) w.add_f64("base_placements", map.base_placements, {m, map.tried, 3});
  w.add_scalar("tried", static_cast<std::int64_t>(map.tried));
  const WorkspaceOptions& o = map.options;
  // The directions of every voxel's sphere, so that a reader needs numpy alone.
  std::vector<double> dirs;
  for (const auto& v : fibonacci_directions(o.directions)) dirs.insert(dirs.end(), {v.x(), v.y(), v.z()});
  w.add_f64("sphere_directions", dirs, {o.directions, 3});
  w.add_f64("grid_origin", {map.grid.origin.x(), map.grid.origin.y(), map.grid.origin.z()}, {3});
  w.add_scalar("grid_size", map.grid.side());
  w.add_i64("grid_shape", {map.grid.n, map.grid.n, map.grid.n}, {3});
  w.add_scalar("hull_voxels", map.hull_voxels);
  w.add_scalar("hull_facets", static_cast<std::int64_t>(map.hull_facets));
  w.add_string("hull", hull_kind_name(o.hull));
  w.add_scalar("shrink", o.map_shrink());
  w.add_scalar("alpha", map.alpha);
  w.add_scalar("reach", map.reach);
  w.add_scalar("voxel_size", o.voxel_size);
  w.add_scalar("directions", static_cast<std::int64_t>(o.directions));
  w.add_scalar("rolls", static_cast<std::int64_t>(o.free_roll ? 0 : o.rolls));
  w.add_bool("free_roll", o.free_roll);
  w.add_bool("any_roll", o.any_roll);
  w.add_string("approach_axis", approach_axis_name(o.approach));
  w.add_scalar("timeout", o.timeout);
  w.add_scalar("epsilon", o.epsilon);
  w.add_scalar("cloud_samples", static_cast<std::int64_t>(o.cloud_samples));
  w.add_u64("seed", {o.seed}, {});
  w.add_i64("shard", {o.shard_index, o.shard_count}, {2});
  w.add_string("chain_hash", map.chain_hash);
  w.add_string("base", map.base);
  w.add_string("tip", map.tip);
  w.add_string("command", command);
  w.add_scalar("ik_calls", map.ik_calls);
  w.add_scalar("cheap_exits", map.cheap_exits);
  w.add_scalar("seconds", map.seconds);
  w.add_scalar("threads", static_cast<std::int64_t>(map.threads_used));
  try {
    w.write(path);
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
}

}  // namespace snakehead
