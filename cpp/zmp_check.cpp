#include "snakehead/zmp_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

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

}  // namespace

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
  if (!(spec.gravity.allFinite() && spec.gravity.z() < 0.0))
    throw InputError("zmp_check: gravity must be finite with g_z < 0 (the ground below)");
  for (long s : spec.contact_shapes) check_shape_index("contact", s, shapes);
  for (long s : spec.clearance_shapes) check_shape_index("clearance", s, shapes);
  for (int j : spec.key_joints)
    if (j < 0 || j >= n) throw InputError("zmp_check: key joint " + std::to_string(j) + " is outside the chain");
}

bool same_spec(const ZmpCheckSpec& a, const ZmpCheckSpec& b) {
  return a.contact_shapes == b.contact_shapes && a.points_per_shape == b.points_per_shape &&
         a.clearance_shapes == b.clearance_shapes && a.ground_key == b.ground_key && a.key_joints == b.key_joints &&
         a.shaped_links == b.shaped_links && a.tolerance == b.tolerance && a.chunk == b.chunk &&
         a.gravity == b.gravity;
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
  const double Mg = M * -spec.gravity.z();  // the weight's share across the ground
  const bool leaning = spec.gravity.x() != 0.0 || spec.gravity.y() != 0.0;  // a slope: the weight pulls along it
  const double Mgx = M * spec.gravity.x(), Mgy = M * spec.gravity.y();
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
      // Eqs. 39-40 (p_z = 0); on a slope the weight's moment about the ground plane adds M (g_x, g_y) c_z
      const double mx = leaning ? Mg * c[0] + Mgx * c[2] : Mg * c[0];
      const double my = leaning ? Mg * c[1] + Mgy * c[2] : Mg * c[1];
      const Eigen::Vector2d p((mx - Ldot[3 * k + 1]) / den, (my + Ldot[3 * k]) / den);
      out.zmp[2 * k] = p.x();
      out.zmp[2 * k + 1] = p.y();
      if (!p.allFinite()) throw InputError("zmp_check: the ZMP is not finite (qd or t out of range)");
      out.margin[k] = polygons.margin(run[k], p);
    }
  });
}

// zmp_check's arguments beyond the spec: T >= 2 strictly increasing times, keep >= 0, not both resume and keep.
void check_arguments(const ZmpCheckSpec& spec, const ShapeSet& shapes, long n, const double* t, long T,
                     const ZmpPrefix* resume, long keep) {
  if (T < 2) throw InputError("zmp_check: at least two samples are needed");
  for (long k = 1; k < T; ++k)
    if (!(t[k] > t[k - 1])) throw InputError("zmp_check: t must increase strictly");
  check_spec(spec, shapes, n);
  if (keep < 0) throw InputError("zmp_check: keep must be >= 0");
  if (keep > 0 && resume != nullptr) throw InputError("zmp_check: give a prefix to resume from or one to keep, not both");
}

// zmp_check's pass over the samples, up to the ZMP: each sample's momenta, CoM, clearance and contact key, and the
// contact runs with their polygons. In blocks of kZmpBlock samples (bounded buffers), each in two steps: 1. each
// sample on its own, split over the core's threads (frames, momenta, CoM, lowest points, clearance, contact key);
// 2. in order, the repeats and the contact runs (a new polygon where the key changes, from the sample's frames again).
class ZmpPass {
 public:
  ZmpPass(const PathChecker& checker, const RigidBodyChain& chain, const ZmpCheckSpec& spec, const double* q,
          const double* qd, long T, ZmpCheck& out)
      : checker_(checker), chain_(chain), spec_(spec), q_(q), qd_(qd), T_(T), n_(checker.n_joints()),
        L_(checker.links()), out_(out), polygons_(spec, checker.shapes(), L_), run_(static_cast<std::size_t>(T)),
        slot_(clearance_slots(spec, lowest_of_)), U_(static_cast<long>(lowest_of_.size())),
        K_(spec.ground_key ? static_cast<long>(chain.joint_child.size()) + 1
                           : static_cast<long>(spec.key_joints.size())),
        lows_(static_cast<std::size_t>(kZmpBlock * U_)), keys_(static_cast<std::size_t>(kZmpBlock * K_)),
        frames_(static_cast<std::size_t>(16 * L_)) {
    out.linear.resize(static_cast<std::size_t>(3 * T));
    out.angular.resize(static_cast<std::size_t>(3 * T));
    out.com.resize(static_cast<std::size_t>(3 * T));
    out.clearance.assign(static_cast<std::size_t>(T), kInf);
  }

  // Takes the prefix's samples over when it matches (see Takeover): to the bit at its own placement, moved at another.
  void take_over(const ZmpPrefix& prefix) {
    const Takeover how = takeover(prefix, checker_, spec_, q_, qd_, T_);
    if (how.kind == Takeover::kNone) return;
    k0_ = prefix.size();
    std::copy(prefix.linear.begin(), prefix.linear.end(), out_.linear.begin());
    std::copy(prefix.angular.begin(), prefix.angular.end(), out_.angular.begin());
    std::copy(prefix.com.begin(), prefix.com.end(), out_.com.begin());
    std::copy(prefix.clearance.begin(), prefix.clearance.end(), out_.clearance.begin());
    std::copy(prefix.run.begin(), prefix.run.end(), run_.begin());
    polygons_.restore(prefix.vertices, prefix.start);
    if (how.kind == Takeover::kMoved) {
      move_samples(how, k0_, out_);
      polygons_.move(how.c, how.s, how.x, how.y);
    }
    previous_ = prefix.last_key;
    run_key_.resize(static_cast<std::size_t>(polygons_.runs()));
    run_key_.back() = previous_;
    out_.resumed = k0_;
  }

  // Every sample after those taken over; keep > 0: the keys of the runs that start in the first keep samples are
  // kept (keep_prefix).
  void run(long keep) {
    for (long b0 = k0_; b0 < T_; b0 += kZmpBlock) {
      const long b1 = std::min(T_, b0 + kZmpBlock);
      each_sample(b0, b1);
      contact_runs(b0, b1, keep);
    }
  }

  // The first min(keep, T) samples' part into p (after run(keep)).
  void keep_prefix(long keep, ZmpPrefix& p) const {
    const long m = std::min(keep, T_);
    const auto m3 = static_cast<std::size_t>(3 * m), mn = static_cast<std::size_t>(m * n_);
    p.model = &checker_.model();
    p.shapes = &checker_.shapes();
    p.origin = checker_.origin().matrix();
    p.spec = spec_;
    p.q.assign(q_, q_ + mn);
    p.qd.assign(qd_, qd_ + mn);
    p.linear.assign(out_.linear.begin(), out_.linear.begin() + m3);
    p.angular.assign(out_.angular.begin(), out_.angular.begin() + m3);
    p.com.assign(out_.com.begin(), out_.com.begin() + m3);
    p.clearance.assign(out_.clearance.begin(), out_.clearance.begin() + m);
    p.run.assign(run_.begin(), run_.begin() + m);
    polygons_.keep(run_[m - 1] + 1, p.vertices, p.start);
    p.last_key = run_key_[static_cast<std::size_t>(run_[m - 1])];
  }

  const std::vector<long>& runs() const { return run_; }
  const SupportRuns& polygons() const { return polygons_; }

 private:
  // Sample k repeats the one before (a hold: ~500 samples a target): its values are that one's, to the bit.
  bool repeats(long k) const {
    const auto nbytes = static_cast<std::size_t>(n_) * sizeof(double);
    return k > 0 && k % spec_.chunk != 0 && std::memcmp(q_ + k * n_, q_ + (k - 1) * n_, nbytes) == 0 &&
           std::memcmp(qd_ + k * n_, qd_ + (k - 1) * n_, nbytes) == 0;
  }

  // Step 1 over samples b0 .. b1 - 1: each on its own (the repeats left to step 2), split over the core's threads.
  void each_sample(long b0, long b1) {
    parallel_for(b1 - b0, kZmpSamplesPerThread, [&](long begin, long end) {
      std::vector<double> own_frames(static_cast<std::size_t>(16 * L_)), key;
      Frames own_work;
      for (long k = b0 + begin; k < b0 + end; ++k)
        if (!repeats(k)) sample(k, b0, own_frames, own_work, key);
    });
  }

  // Sample k's frames, momenta, CoM, lowest points, clearance and contact key (buffers: the calling thread's own).
  void sample(long k, long b0, std::vector<double>& frames, Frames& work, std::vector<double>& key) {
    const Eigen::Map<const Eigen::VectorXd> qk(q_ + k * n_, n_);
    checker_.model().check_configuration(qk);
    checker_.world_frames(qk, frames.data(), work);
    momenta(chain_, frames.data(), qd_ + k * n_, 1, L_, &out_.linear[3 * k], &out_.angular[3 * k], &out_.com[3 * k]);
    double* low = &lows_[static_cast<std::size_t>((k - b0) * U_)];
    lowest_z(frames.data(), 1, L_, checker_.shapes(), lowest_of_.data(), U_, low);
    for (long c : slot_) out_.clearance[k] = std::min(out_.clearance[k], low[static_cast<std::size_t>(c)]);
    contact_key(spec_, chain_.joint_child, checker_.shapes(), low, q_ + k * n_, key);
    if (static_cast<long>(key.size()) != K_) throw std::logic_error("zmp_check: a contact key of another length");
    std::copy(key.begin(), key.end(), keys_.begin() + (k - b0) * K_);
  }

  // Step 2 over samples b0 .. b1 - 1, in order: a repeat takes the sample before's values; a sample whose contact
  // key differs from the last run's (or that starts a chunk) starts a run with a new polygon.
  void contact_runs(long b0, long b1, long keep) {
    for (long k = b0; k < b1; ++k) {
      if (repeats(k)) {
        repeat(k);
        continue;
      }
      const auto key = keys_.begin() + (k - b0) * K_;
      if (k % spec_.chunk == 0 || previous_.size() != static_cast<std::size_t>(K_) ||
          !std::equal(key, key + K_, previous_.begin())) {
        checker_.world_frames(Eigen::Map<const Eigen::VectorXd>(q_ + k * n_, n_), frames_.data(), work_);
        polygons_.add(frames_.data(), L_, &lows_[static_cast<std::size_t>((k - b0) * U_)]);
        previous_.assign(key, key + K_);
        if (keep > 0 && k < keep) run_key_.push_back(previous_);
      }
      run_[k] = polygons_.runs() - 1;
    }
  }

  // Sample k's values are those of sample k - 1.
  void repeat(long k) {
    for (int c = 0; c < 3; ++c) {
      out_.linear[3 * k + c] = out_.linear[3 * (k - 1) + c];
      out_.angular[3 * k + c] = out_.angular[3 * (k - 1) + c];
      out_.com[3 * k + c] = out_.com[3 * (k - 1) + c];
    }
    out_.clearance[k] = out_.clearance[k - 1];
    run_[k] = run_[k - 1];
  }

  const PathChecker& checker_;
  const RigidBodyChain& chain_;
  const ZmpCheckSpec& spec_;
  const double* q_;
  const double* qd_;
  const long T_, n_, L_;
  ZmpCheck& out_;
  SupportRuns polygons_;
  std::vector<long> run_;                     // each sample's run
  std::vector<double> previous_;              // the contact key of the last run
  std::vector<std::vector<double>> run_key_;  // each run's contact key (a kept prefix ends with its last)
  long k0_ = 0;                               // samples taken over
  // one lowest_z per shape and sample: the contact shapes, then the clearance shapes that are not among them
  std::vector<long> lowest_of_;
  const std::vector<long> slot_;  // each clearance shape's place in lowest_of_
  const long U_, K_;              // lowest_of_'s and contact_key's lengths
  std::vector<double> lows_, keys_;  // a block's lowest z and contact keys, sample by sample
  std::vector<double> frames_;       // step 2's frames
  Frames work_;
};

}  // namespace

ZmpCheck zmp_check(const PathChecker& checker, const RigidBodyChain& chain, const ZmpCheckSpec& spec,
                   const double* t, const double* q, const double* qd, long T, const ZmpPrefix* resume, long keep,
                   ZmpPrefix* kept) {
  check_arguments(spec, checker.shapes(), checker.n_joints(), t, T, resume, keep);
  ZmpCheck out;
  ZmpPass pass(checker, chain, spec, q, qd, T, out);
  if (resume != nullptr) pass.take_over(*resume);
  pass.run(keep);
  if (keep > 0 && kept != nullptr) pass.keep_prefix(keep, *kept);
  zmp_and_margins(chain, spec, t, T, pass.runs(), pass.polygons(), out);
  return out;
}

}  // namespace snakehead
