#include "snakehead/trac_ik.hpp"

#include "snakehead/core_threads.hpp"
#include "snakehead/kinematics.hpp"
#include "snakehead/limits.hpp"
#include "snakehead/parallel_for.hpp"
#include "snakehead/random_numbers.hpp"
#include "snakehead/worker_pool.hpp"

#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_nr_jl.hpp>
#include <kdl/chainiksolvervel_pinv.hpp>
#include <nlopt.hpp>

#include <Eigen/Cholesky>
#include <Eigen/SVD>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <climits>
#include <cmath>
#include <mutex>

namespace snakehead {
namespace {

using Clock = std::chrono::steady_clock;

// Nominal kinematics evaluations per second that turn a seeded call's timeout into an evaluation budget: about the
// rate of a seeded call on an unreachable target of the 7-DOF head (Newton and SLSQP interleaved, SLSQP's own
// bookkeeping included) on the development machine, so that there a failing seeded call takes about its timeout
// (bench/RESULTS.md).
constexpr double kEvaluationsPerSecond = 7.0e5;
// A seeded call reads no clock at all: the budget alone ends it (every local search is bounded -- kNewtonIterations,
// kSqpEvaluations -- and each makes at least one evaluation, so the budget is always reached). It takes about its
// timeout at the nominal rate, longer on a slower, loaded or sanitized machine, and gives the same answer whatever
// the load.

// Local-search limits. A Newton descent that has not converged in this many iterations is treated as
// stuck; so is an SLSQP run that used its evaluations.
constexpr int kNewtonIterations = 60;
constexpr int kSqpEvaluations = 120;
constexpr double kMaxStep = 0.6;  // rad (or m): largest joint change of one Newton step
constexpr double kLambda0 = 1e-2;  // initial Levenberg-Marquardt damping
// A descent must fall below kProgress times its error of kProgressWindow iterations earlier, else it restarts: on the
// default robot's 6- and 7-DOF heads quick abandonment and restarts beat long descents (bench/RESULTS.md).
constexpr int kProgressWindow = 3;
constexpr double kProgress = 0.3;
// Share of the timeout that a Speed call spends on KDL-RR in the calling thread before it starts the race: most
// targets are solved before it ends, without a thread hand-off (bench/RESULTS.md).
constexpr double kInlineFraction = 0.05;

// ---------------------------------------------------------------------------------------------------------
// One call's problem and shared control.

struct Problem {
  const ChainModel& model;
  Eigen::Isometry3d target;
  Vector6d bounds;
  double epsilon;
  SolveType type;
  const Eigen::VectorXd& q_init;
  const SamplingRange& range;  // where restarts are drawn from
};

struct CallControl {
  std::atomic<bool> stop{false};
  std::mutex result;     // guards `claimed` and both searches' Best (the racing threads offer under it)
  bool claimed = false;  // Speed: the first solution claims the win
  Clock::time_point deadline;
  bool budgeted = false;  // seeded: bounded by evaluations (single thread, so a plain counter)
  long evals = 0;
  long max_evals = LONG_MAX;
};

// The best solution a search has seen; score: lower is better.
struct Best {
  bool found = false;
  Eigen::VectorXd q;
  double score = std::numeric_limits<double>::infinity();
  int count = 0;
};

double manipulability_score(SolveType type, const Matrix6Xd& jac) {
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(jac);
  const auto& s = svd.singularValues();  // min(6, n) values, descending
  if (type == SolveType::Manip1) return -s.prod();  // = sqrt(det(J J^T)) for n >= 6
  return s[0] > 0 ? -(s[s.size() - 1] / s[0]) : 0.0;
}

// One solver's per-call state: workspace, generator, best solution (guarded by c.result).
class Search {
 public:
  Search(const Problem& p, CallControl& c, SplitMix64& rng)
      : p(p), c(c), rng(rng), n(p.model.n_joints()), jac(6, n), dr(6, n), jac_try(6, n), dr_try(6, n), dr_step(6, n), dq(n),
        q_try(n) {}

  bool should_stop() {
    if (c.stop.load(std::memory_order_relaxed)) return true;
    if (c.budgeted) return c.evals >= c.max_evals ? halt() : false;  // seeded: the budget, never the clock
    if (Clock::now() >= c.deadline) return halt();
    return false;
  }
  bool halt() {
    c.stop.store(true, std::memory_order_relaxed);
    return true;
  }

  // FK + Jacobian + residual at q into (tip, jac, r, dr); returns the raw error.
  Vector6d evaluate(const Eigen::VectorXd& q, Matrix6Xd& J, Vector6d& r, Matrix6Xd& D) {
    evals.fetch_add(1, std::memory_order_relaxed);
    if (c.budgeted) ++c.evals;  // seeded calls run in one thread; racing threads never touch the counter
    Eigen::Isometry3d tip;
    tip_jacobian(p.model, q, J, tip);
    return residual_and_jacobian(p.target, tip, J, p.bounds, r, D);
  }

  // Records a solution (q within the limits, pose reached).
  void offer(const Eigen::VectorXd& q, const Matrix6Xd& J) {
    if (p.type == SolveType::Speed) {
      {
        std::lock_guard<std::mutex> lock(c.result);
        if (!c.claimed) {
          c.claimed = true;
          best.found = true;
          best.q = q;
          best.count = 1;
        }
      }
      c.stop.store(true, std::memory_order_relaxed);
      return;
    }
    double score;
    if (p.type == SolveType::Distance)
      score = (q - p.q_init).squaredNorm();
    else
      score = manipulability_score(p.type, J);
    std::lock_guard<std::mutex> lock(c.result);
    ++best.count;
    if (!best.found || score < best.score) {
      best.found = true;
      best.q = q;
      best.score = score;
    }
  }

  void random_configuration(Eigen::VectorXd& q) { p.range.draw(rng, q); }

  void clamp(Eigen::VectorXd& q) const {
    q = q.cwiseMax(p.model.lower()).cwiseMin(p.model.upper());
  }

  const Problem& p;
  CallControl& c;
  SplitMix64& rng;
  const int n;
  Matrix6Xd jac, dr, jac_try, dr_try, dr_step;
  Eigen::VectorXd dq, q_try;
  Best best;
  std::atomic<long> evals{0};  // this search's own count (statistics; read by the other thread)
};

// ---------------------------------------------------------------------------------------------------------
// KDL-RR's local step: Levenberg-Marquardt-damped Newton-Raphson on the residual, with the joint limits
// enforced by clamping. Returns true when the target was reached (q is then the solution). A descent is
// abandoned as a local minimum when the damping has to grow without bound (no step reduces the error),
// when the error stops decreasing, or after kNewtonIterations.
bool newton_descent(Search& s, Eigen::VectorXd& q) {
  if (s.should_stop()) return false;
  Vector6d r, r_try;
  Vector6d e = s.evaluate(q, s.jac, r, s.dr);
  if (pose_reached(e, s.p.bounds, s.p.epsilon)) {
    s.offer(q, s.jac);
    return true;
  }
  double err = r.squaredNorm();
  double lambda = kLambda0;
  double checkpoint = err;
  for (int it = 0; it < kNewtonIterations; ++it) {
    if (s.should_stop()) return false;
    // dq = -D^T (D D^T + lambda I)^{-1} r: the 6x6 form of the damped normal equations. A joint at a
    // limit that the step would push further out is taken out of the step (its column zeroed) and the
    // step recomputed, so the other joints do the work instead of the step being clamped away.
    s.dr_step = s.dr;
    for (int pass = 0; pass < 3; ++pass) {
      Eigen::Matrix<double, 6, 6> A;
      A.noalias() = s.dr_step * s.dr_step.transpose();
      A.diagonal().array() += lambda;
      // A is symmetric positive definite (lambda > 0): Cholesky, with LDLT as the fallback when rounding
      // makes a nearly singular A lose definiteness.
      const Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(A);
      const Vector6d y = llt.info() == Eigen::Success ? Vector6d(llt.solve(r)) : Vector6d(A.ldlt().solve(r));
      s.dq.noalias() = -s.dr_step.transpose() * y;
      bool blocked = false;
      for (int i = 0; i < s.n; ++i) {
        if (s.dq[i] == 0.0) continue;
        if ((s.dq[i] < 0 && q[i] <= s.p.model.lower()[i]) || (s.dq[i] > 0 && q[i] >= s.p.model.upper()[i])) {
          s.dr_step.col(i).setZero();
          blocked = true;
        }
      }
      if (!blocked) break;
    }
    const double big = s.dq.cwiseAbs().maxCoeff();
    if (big > kMaxStep) s.dq *= kMaxStep / big;
    s.q_try = q + s.dq;
    s.clamp(s.q_try);
    if ((s.q_try - q).cwiseAbs().maxCoeff() < 1e-12) return false;  // pinned at the limits: a local minimum
    e = s.evaluate(s.q_try, s.jac_try, r_try, s.dr_try);
    if (pose_reached(e, s.p.bounds, s.p.epsilon)) {
      q = s.q_try;
      s.offer(q, s.jac_try);
      return true;
    }
    const double err_try = r_try.squaredNorm();
    if (err_try < err) {
      q.swap(s.q_try);
      s.jac.swap(s.jac_try);
      s.dr.swap(s.dr_try);
      r = r_try;
      err = err_try;
      lambda = std::max(lambda * 0.2, 1e-12);
    } else {
      lambda *= 10.0;
      if (lambda > 1e4) return false;
    }
    // Newton converges quadratically near a solution; a descent whose error does not fall below kProgress
    // times its value kProgressWindow iterations earlier is creeping into a local minimum: restart instead.
    if ((it + 1) % kProgressWindow == 0) {
      if (err > kProgress * checkpoint) return false;
      checkpoint = err;
    }
  }
  return false;
}

// ---------------------------------------------------------------------------------------------------------
// SQP: SLSQP on f(q) = |r(q)|^2 with grad = 2 D^T r, the joint limits as bounds.

struct SqpContext {
  Search* s;
  nlopt::opt* opt;
  bool found = false;
};

double sqp_objective(unsigned n, const double* x, double* grad, void* data) {
  auto* ctx = static_cast<SqpContext*>(data);
  Search& s = *ctx->s;
  if (s.should_stop()) {
    ctx->opt->force_stop();
    if (grad) std::fill(grad, grad + n, 0.0);
    return 0.0;
  }
  // SLSQP may step a hair outside the bounds; evaluate (and report) the clamped point.
  s.q_try = Eigen::Map<const Eigen::VectorXd>(x, n);
  s.clamp(s.q_try);
  Vector6d r;
  const Vector6d e = s.evaluate(s.q_try, s.jac_try, r, s.dr_try);
  if (pose_reached(e, s.p.bounds, s.p.epsilon)) {
    ctx->found = true;
    s.offer(s.q_try, s.jac_try);
    ctx->opt->force_stop();  // this local search is done; Speed stops everything, the others restart
  }
  if (grad) Eigen::Map<Eigen::VectorXd>(grad, n).noalias() = 2.0 * s.dr_try.transpose() * r;
  return r.squaredNorm();
}

class SqpSolver {
 public:
  explicit SqpSolver(Search& s) : s_(s), opt_(nlopt::LD_SLSQP, static_cast<unsigned>(s.n)), x_(s.n) {
    const auto& lo = s.p.model.lower();
    const auto& hi = s.p.model.upper();
    opt_.set_lower_bounds(std::vector<double>(lo.data(), lo.data() + lo.size()));
    opt_.set_upper_bounds(std::vector<double>(hi.data(), hi.data() + hi.size()));
    opt_.set_stopval(s.p.epsilon * s.p.epsilon);  // |r|^2 <= eps^2 implies every |r_i| <= eps
    opt_.set_xtol_abs(1e-10);
    opt_.set_ftol_abs(1e-16);
    opt_.set_maxeval(kSqpEvaluations);
  }

  // One local search from q (within the limits). True when it reached the target.
  bool descent(const Eigen::VectorXd& q) {
    if (s_.should_stop()) return false;
    SqpContext ctx{&s_, &opt_};
    opt_.set_min_objective(sqp_objective, &ctx);
    if (!s_.c.budgeted) {
      const double left = std::chrono::duration<double>(s_.c.deadline - Clock::now()).count();
      if (left <= 0) return false;
      opt_.set_maxtime(left);
    }
    std::copy(q.data(), q.data() + s_.n, x_.begin());
    double f = 0;
    try {
      opt_.optimize(x_, f);
    } catch (...) {
      // forced stop, round-off limited, or SLSQP's own failure: the search just moves on
    }
    return ctx.found;
  }

 private:
  Search& s_;
  nlopt::opt opt_;
  std::vector<double> x_;
};

// ---------------------------------------------------------------------------------------------------------
// Search loops.

// KDL-RR from `start`, then random restarts, until stopped.
void kdl_rr_loop(Search& s, const Eigen::VectorXd& start) {
  Eigen::VectorXd q = start;
  for (;;) {
    newton_descent(s, q);
    if (s.should_stop()) return;
    s.random_configuration(q);
  }
}

void sqp_loop(Search& s, const Eigen::VectorXd& start) {
  SqpSolver sqp(s);
  Eigen::VectorXd q = start;
  for (;;) {
    sqp.descent(q);
    if (s.should_stop()) return;
    s.random_configuration(q);
  }
}

// Both solvers in one thread: the seeded and the batch schedule. As in a raced call, KDL-RR first runs alone
// for kInlineFraction of the budget (evaluations when seeded, else the clock); then the two share the thread
// as two threads would share the machine: whichever has made fewer kinematics evaluations runs its next
// local search (SQP first, from q_init). Every decision depends on counts only, so a seeded run repeats.
void interleaved_loop(Search& nr, Search& sq, Clock::time_point inline_end) {
  const long inline_evals = static_cast<long>(kInlineFraction * static_cast<double>(nr.c.max_evals));
  auto inline_phase = [&] { return nr.c.budgeted ? nr.evals < inline_evals : Clock::now() < inline_end; };
  Eigen::VectorXd qn = nr.p.q_init, qs = nr.p.q_init;
  newton_descent(nr, qn);
  while (!nr.should_stop() && inline_phase()) {
    nr.random_configuration(qn);
    newton_descent(nr, qn);
  }
  if (nr.should_stop()) return;
  SqpSolver sqp(sq);
  for (;;) {
    if (sq.evals <= nr.evals) {
      sqp.descent(qs);
      sq.random_configuration(qs);
    } else {
      nr.random_configuration(qn);
      newton_descent(nr, qn);
    }
    if (nr.should_stop()) return;
  }
}

// Picks the better of the two searches' results (ties: KDL-RR, for determinism).
const Best* pick(const Best& a, const Best& b) {
  if (a.found && (!b.found || a.score <= b.score)) return &a;
  if (b.found) return &b;
  return nullptr;
}

bool finite_isometry(const Eigen::Isometry3d& t) { return t.matrix().allFinite(); }

}  // namespace

// ---------------------------------------------------------------------------------------------------------

SolveType solve_type_from_string(const std::string& name) {
  if (name == "Speed") return SolveType::Speed;
  if (name == "Distance") return SolveType::Distance;
  if (name == "Manip1") return SolveType::Manip1;
  if (name == "Manip2") return SolveType::Manip2;
  throw InputError("unknown solve type '" + name + "'; expected Speed, Distance, Manip1 or Manip2");
}

const char* to_string(SolveType type) {
  switch (type) {
    case SolveType::Speed: return "Speed";
    case SolveType::Distance: return "Distance";
    case SolveType::Manip1: return "Manip1";
    case SolveType::Manip2: return "Manip2";
  }
  return "?";
}

void check_options(const TracIKOptions& o) {
  check_timeout(o.timeout, "timeout");
  if (!(o.epsilon > 0) || !std::isfinite(o.epsilon))
    throw InputError("epsilon must be a positive finite number, got " + number_text(o.epsilon));
  for (int i = 0; i < 6; ++i)
    if (std::isnan(o.bounds[i]) || o.bounds[i] < 0)
      throw InputError("bounds must be 6 tolerances >= 0 (inf leaves an axis free); bounds[" + std::to_string(i) +
                       "] = " + number_text(o.bounds[i]));
  switch (o.solve_type) {
    case SolveType::Speed: case SolveType::Distance: case SolveType::Manip1: case SolveType::Manip2: break;
    default: throw InputError("unknown solve type");
  }
}

void check_pose(const Eigen::Isometry3d& target, const char* what) {
  if (!finite_isometry(target)) throw InputError(std::string(what) + " contains NaN or inf");
  const Eigen::Matrix4d& m = target.matrix();
  if ((m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-9)
    throw InputError(std::string(what) + ": last row must be [0, 0, 0, 1]");
  const Eigen::Matrix3d R = m.topLeftCorner<3, 3>();
  const double err = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (err > 1e-6 || R.determinant() < 0)
    throw InputError(std::string(what) + ": rotation is not orthonormal and right-handed (error " +
                     std::to_string(err) + ", det " + std::to_string(R.determinant()) + ")");
}

struct TracIK::Impl {
  std::shared_ptr<const ChainModel> model;
  TracIKOptions options;
  std::shared_ptr<const SamplingRange> range;

  Impl(std::shared_ptr<const ChainModel> m, const TracIKOptions& o)
      : model(std::move(m)), options(o), range(std::make_shared<const SamplingRange>(*model)) {}

  void check_q_init(const Eigen::Ref<const Eigen::VectorXd>& q) const {
    model->check_configuration(q, "q_init");
    for (int i = 0; i < q.size(); ++i)
      if (q[i] < model->lower()[i] - 1e-9 || q[i] > model->upper()[i] + 1e-9)
        throw InputError("q_init[" + std::to_string(i) + "] = " + std::to_string(q[i]) + " is outside the limits [" +
                         std::to_string(model->lower()[i]) + ", " + std::to_string(model->upper()[i]) + "]");
  }

  // mode: how the two solvers are scheduled.
  enum class Schedule { Race, Interleaved };

  // Everything one call's searches share. Heap-allocated and shared with a racing SQP job, so that the caller can
  // return as soon as it has an answer without waiting for the worker to notice the stop (a worker that the
  // scheduler has parked could otherwise hold the caller for milliseconds); it holds the model and the sampling
  // range too, so that the job may outlive the solver.
  struct CallState {
    CallState(std::shared_ptr<const ChainModel> m, std::shared_ptr<const SamplingRange> r,
              const Eigen::Isometry3d& target, const Eigen::VectorXd& q0, const TracIKOptions& o)
        : model(std::move(m)), range(std::move(r)), q_init(q0),
          p{*model, target, o.bounds, o.epsilon, o.solve_type, q_init, *range}, sq(p, c, rng_sq) {}
    std::shared_ptr<const ChainModel> model;
    std::shared_ptr<const SamplingRange> range;
    Eigen::VectorXd q_init;
    Problem p;
    CallControl c;
    SplitMix64 rng_sq;
    Search sq;  // the SQP half
  };

  IKResult run(const Eigen::Isometry3d& target, const Eigen::VectorXd& q_init, const TracIKOptions& o,
               IKAlgorithm algorithm, Schedule schedule, std::uint64_t stream) const {
    const auto t0 = Clock::now();
    auto st = std::make_shared<CallState>(model, range, target, q_init, o);
    SplitMix64 rng_nr;
    if (o.seed) schedule = Schedule::Interleaved;
    start(o, stream, t0, st->c, rng_nr, st->rng_sq);
    Search nr(st->p, st->c, rng_nr);
    Search& sq = st->sq;
    const auto inline_end = deadline_after(t0, kInlineFraction * o.timeout);
    if (algorithm == IKAlgorithm::KdlRR) {
      kdl_rr_loop(nr, q_init);
    } else if (algorithm == IKAlgorithm::Sqp) {
      sqp_loop(sq, q_init);
    } else if (schedule == Schedule::Interleaved) {
      interleaved_loop(nr, sq, inline_end);
    } else {
      race(st, nr, o.solve_type == SolveType::Speed, inline_end);
    }
    return result(target, q_init, t0, nr, sq, st->c);
  }

  // The call's control and generators: a seeded call is bounded by its evaluation budget and draws from the streams
  // of (seed, stream); an unseeded one by the clock, its generators seeded by this thread's generator.
  static void start(const TracIKOptions& o, std::uint64_t stream, Clock::time_point t0, CallControl& c,
                    SplitMix64& rng_nr, SplitMix64& rng_sq) {
    if (o.seed) {
      c.budgeted = true;
      // (timeout <= limits::kMaxTimeoutSeconds, so the budget fits a long: at most 6e10 evaluations)
      c.max_evals = std::max(50L, static_cast<long>(o.timeout * kEvaluationsPerSecond));
      c.deadline = Clock::time_point::max();  // unused: a seeded call never reads the clock (should_stop)
      const std::uint64_t base = splitmix64(*o.seed ^ splitmix64(stream));
      rng_nr.seed(splitmix64(base ^ 0x6E72ULL));
      rng_sq.seed(splitmix64(base ^ 0x737170ULL));
    } else {
      c.deadline = deadline_after(t0, o.timeout);
      rng_nr.seed(thread_generator()());
      rng_sq.seed(thread_generator()());
    }
  }

  // Race: KDL-RR in this thread, SQP on the worker pool, until one solves (Speed) or the time is up. For Speed,
  // KDL-RR first runs alone in this thread for a short while (kInlineFraction of the timeout): its descent from q_init
  // solves most targets in tens of microseconds, less than it takes to wake a worker thread and to stop it again.
  // Only targets that survive this are raced.
  static void race(const std::shared_ptr<CallState>& st, Search& nr, bool speed, Clock::time_point inline_end) {
    Eigen::VectorXd q = st->q_init;
    if (speed) {
      newton_descent(nr, q);
      while (!nr.should_stop() && Clock::now() < inline_end) {
        nr.random_configuration(q);
        newton_descent(nr, q);
      }
    }
    if (nr.should_stop()) return;
    // The job owns a reference to the call state; it never touches this stack frame.
    auto job = std::make_shared<WorkerPool::Job>([st] {
      try {
        sqp_loop(st->sq, st->q_init);
      } catch (...) {  // e.g. std::bad_alloc: give up the SQP half, never take the process down
        st->c.stop.store(true);
      }
    });
    WorkerPool& pool = WorkerPool::process();
    pool.submit(job);
    try {
      if (speed) {
        for (;;) {  // KDL-RR restarts
          nr.random_configuration(q);
          newton_descent(nr, q);
          if (nr.should_stop()) break;
        }
      } else {
        kdl_rr_loop(nr, st->q_init);
      }
    } catch (...) {
      st->c.stop.store(true);
      pool.cancel(job);
      throw;
    }
    st->c.stop.store(true);
    pool.cancel(job);  // if it is running, it stops at its next evaluation, on its own time
  }

  // The better of the two searches' solutions (q_init when neither found one) and the call's figures.
  IKResult result(const Eigen::Isometry3d& target, const Eigen::VectorXd& q_init, Clock::time_point t0,
                  const Search& nr, const Search& sq, CallControl& c) const {
    IKResult res;
    {
      std::lock_guard<std::mutex> lock(c.result);  // the SQP half may still be running
      const Best* b = pick(nr.best, sq.best);
      res.found = b != nullptr;
      res.q = b ? b->q : q_init;
      res.solutions = nr.best.count + sq.best.count;
    }
    res.error = pose_error(target, forward_kinematics(*model, res.q));
    res.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    res.evaluations = nr.evals.load() + sq.evals.load();
    return res;
  }
};

TracIK::TracIK(const ChainModel& model, const TracIKOptions& options)
    : TracIK(std::make_shared<const ChainModel>(model), options) {}

TracIK::TracIK(std::shared_ptr<const ChainModel> model, const TracIKOptions& options) {
  if (!model) throw InputError("TracIK needs a chain model");
  if (model->n_joints() < 1) throw InputError("TracIK needs a chain with at least one moving joint");
  if (model->n_joints() > limits::kMaxIKJoints)
    throw InputError("TracIK handles chains of at most " + std::to_string(limits::kMaxIKJoints) +
                     " joints (its SQP half needs memory growing with the square of the joint count); this chain has " +
                     std::to_string(model->n_joints()));
  check_options(options);
  impl_ = std::make_unique<Impl>(std::move(model), options);
}

TracIK::~TracIK() = default;

const ChainModel& TracIK::model() const { return *impl_->model; }
std::shared_ptr<const ChainModel> TracIK::shared_model() const { return impl_->model; }
const TracIKOptions& TracIK::options() const { return impl_->options; }
int TracIK::n_joints() const { return impl_->model->n_joints(); }
int TracIK::n_workers() const { return hardware_threads(); }

bool TracIK::solve(const Eigen::Isometry3d& target, const Eigen::Ref<const Eigen::VectorXd>& q_init,
                   Eigen::VectorXd& q_out) const {
  return solve(target, q_init, impl_->options.bounds, q_out);
}

bool TracIK::solve(const Eigen::Isometry3d& target, const Eigen::Ref<const Eigen::VectorXd>& q_init,
                   const Vector6d& bounds, Eigen::VectorXd& q_out) const {
  TracIKOptions o = impl_->options;
  o.bounds = bounds;
  IKResult r = solve_ex(target, q_init, o);
  q_out = std::move(r.q);
  return r.found;
}

IKResult TracIK::solve_ex(const Eigen::Isometry3d& target, const Eigen::Ref<const Eigen::VectorXd>& q_init,
                          const TracIKOptions& options, IKAlgorithm algorithm) const {
  check_options(options);
  check_pose(target);
  impl_->check_q_init(q_init);
  Eigen::VectorXd q0 = q_init.cwiseMax(impl_->model->lower()).cwiseMin(impl_->model->upper());
  return impl_->run(target, q0, options, algorithm, Impl::Schedule::Race, 0);
}

void TracIK::solve_many(const std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>>& targets,
                        const Eigen::Ref<const Eigen::MatrixXd>& q_inits, Eigen::MatrixXd& q_out,
                        std::vector<bool>& ok, const std::vector<std::uint64_t>* streams) const {
  const int n = n_joints();
  const auto T = static_cast<Eigen::Index>(targets.size());
  if (streams != nullptr && static_cast<Eigen::Index>(streams->size()) != T)
    throw InputError("streams must hold one value per target (" + std::to_string(T) + "), got " +
                     std::to_string(streams->size()));
  if (q_inits.rows() != n || q_inits.cols() != T)
    throw InputError("q_inits must be " + std::to_string(n) + " x " + std::to_string(T) + " (one column per target), got " +
                     std::to_string(q_inits.rows()) + " x " + std::to_string(q_inits.cols()));
  for (Eigen::Index k = 0; k < T; ++k) {
    check_pose(targets[k], ("targets[" + std::to_string(k) + "]").c_str());
    impl_->check_q_init(q_inits.col(k));
  }
  q_out.resize(n, T);
  std::vector<char> found(static_cast<std::size_t>(T), 0);
  // One target at a time to each thread, the calling thread's included; at most core_threads() threads, and no more
  // than the machine has (more threads than cores would let the scheduler park a thread, mid-target, for longer than
  // a timeout).
  parallel_for_each(T, std::min(hardware_threads(), core_threads()), [&](int, long k) {
    Eigen::VectorXd q0 = q_inits.col(k).cwiseMax(impl_->model->lower()).cwiseMin(impl_->model->upper());
    const std::uint64_t stream = streams != nullptr ? (*streams)[static_cast<std::size_t>(k)] : static_cast<std::uint64_t>(k);
    IKResult r = impl_->run(targets[k], q0, impl_->options, IKAlgorithm::TracIK, Impl::Schedule::Interleaved, stream);
    q_out.col(k) = r.q;
    found[static_cast<std::size_t>(k)] = r.found;
  });
  ok.assign(found.begin(), found.end());
}

// ---------------------------------------------------------------------------------------------------------

bool kdl_nr_jl_ik(const ChainModel& model, const Eigen::Isometry3d& target,
                  const Eigen::Ref<const Eigen::VectorXd>& q_init, Eigen::VectorXd& q_out, double timeout,
                  double epsilon) {
  check_pose(target);
  model.check_configuration(q_init, "q_init");
  check_timeout(timeout, "timeout");
  if (!(epsilon > 0) || !std::isfinite(epsilon)) throw InputError("epsilon must be a positive finite number");
  const auto deadline = deadline_after(Clock::now(), timeout);
  const KDL::Chain& chain = model.kdl_chain();
  const unsigned n = chain.getNrOfJoints();
  KDL::JntArray lo(n), hi(n), q(n), out(n);
  lo.data = model.lower();
  hi.data = model.upper();
  q.data = q_init;
  KDL::ChainFkSolverPos_recursive fk(chain);
  KDL::ChainIkSolverVel_pinv vik(chain);
  // One iteration per call so that the clock is checked between iterations (KDL itself has no timeout);
  // each call continues from the previous result, which is exactly KDL's own iteration.
  KDL::ChainIkSolverPos_NR_JL ik(chain, lo, hi, fk, vik, 1, epsilon);
  KDL::Frame f;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) f.M(r, c) = target.linear()(r, c);
    f.p[r] = target.translation()[r];
  }
  bool ok = false;
  while (Clock::now() < deadline) {
    const int rc = ik.CartToJnt(q, f, out);
    q = out;
    if (rc >= 0) {
      ok = true;
      break;
    }
  }
  q_out = q.data;
  return ok;
}

}  // namespace snakehead
