// TRAC-IK (Beeson and Ames, Humanoids 2015), written for snakehead from the paper.
//
// Two local solvers search for joint angles within the limits that put the chain's tip at a target pose:
//  - KDL-RR: Newton-Raphson (damped least squares) with joint limits, local-minimum detection and random
//    restarts within the limits;
//  - SQP: NLopt's SLSQP on the sum of squared pose residuals, the joint limits as bounds, random restarts.
// They run concurrently; with SolveType::Speed the first solution wins and the other is stopped. The
// other solve types keep searching until the timeout and return the best solution found
// (Distance: closest to q_init; Manip1: largest sqrt(det(J J^T)); Manip2: largest sigma_min / sigma_max).
//
// The pose error, per-axis tolerances and the convergence test are those of pose_error.hpp.
//
// Threads. The SQP half of a raced call runs on the core's worker pool (worker_pool.hpp). A Speed call
// first runs KDL-RR alone in the calling thread for 5 % of the timeout: its descent from q_init solves most
// targets in tens of microseconds, with no thread hand-off at all. Only then is the SQP search handed to a
// worker while the caller continues with KDL-RR; the first solution stops both, and the caller returns at
// once (the worker's state is shared, not on the caller's stack, so the caller never waits for a worker
// that the scheduler has parked). The other solve types race from the start, until the timeout. solve() is
// const and keeps all per-call state on the stack or in that shared call state: one TracIK may be called
// from any number of threads at once.
//
// Fork. A TracIK may be used and destroyed in a forked child of the process that made it (os.fork, a fork-context
// process pool): the child neither uses nor joins the parent's workers, which it does not have, and starts
// workers of its own when it first needs them (worker_pool.hpp).
//
// Determinism. Without a seed, restarts draw from a per-thread random generator and the race is decided
// by timing. With a seed, the call is a pure function of (model, target, q_init, options): both solvers
// run interleaved in the calling thread (KDL-RR alone first, as in a raced call; then whichever solver has
// made fewer kinematics evaluations runs its next local search) from random generators derived from the
// seed alone (no call counter), and the search is bounded by a budget of kinematics evaluations derived
// from the timeout (kEvaluationsPerSecond in trac_ik.cpp) instead of the clock. A seeded call reads no clock: every
// local search is bounded and counts its evaluations, so the budget always ends the call, and the answer is the same
// on a loaded, slow or sanitized machine (where the call takes longer than its timeout: about timeout x the nominal
// rate / the machine's rate).
#pragma once

#include "snakehead/model.hpp"
#include "snakehead/pose_error.hpp"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace snakehead {

enum class SolveType { Speed, Distance, Manip1, Manip2 };

// "Speed", "Distance", "Manip1", "Manip2" (throws InputError otherwise) and back.
SolveType solve_type_from_string(const std::string& name);
const char* to_string(SolveType type);

struct TracIKOptions {
  double timeout = 0.005;  // s, > 0: wall-clock budget of one solve (seeded: an evaluation budget, see above)
  double epsilon = 1e-5;   // > 0: allowed residual per axis (m, rad)
  SolveType solve_type = SolveType::Speed;
  // Per-axis tolerances of the pose error (vx vy vz wx wy wz, target frame), each >= 0 or +inf.
  Vector6d bounds = Vector6d::Zero();
  std::optional<std::uint64_t> seed;  // set: reproducible results (see above)
};

// Throws InputError unless the options are valid (timeout > 0 and finite, epsilon > 0 and finite, bounds >= 0
// and not NaN).
void check_options(const TracIKOptions& options);

// Which solvers a call may use: TRAC-IK runs both; the others are for benchmarks and tests.
enum class IKAlgorithm { TracIK, KdlRR, Sqp };

struct IKResult {
  bool found = false;
  Eigen::VectorXd q;        // the solution when found (within the limits), else q_init
  Vector6d error = Vector6d::Zero();  // pose_error(target, fk(q))
  int solutions = 0;        // distinct solutions seen (more than 1 only for non-Speed solve types)
  double seconds = 0.0;     // wall-clock time of the call
  long evaluations = 0;     // kinematics evaluations (FK + Jacobian) made by both solvers
};

class TracIK {
 public:
  // The solver keeps its own shared copy of the model.
  explicit TracIK(const ChainModel& model, const TracIKOptions& options = {});
  explicit TracIK(std::shared_ptr<const ChainModel> model, const TracIKOptions& options = {});
  ~TracIK();
  TracIK(const TracIK&) = delete;
  TracIK& operator=(const TracIK&) = delete;

  const ChainModel& model() const;
  std::shared_ptr<const ChainModel> shared_model() const;
  const TracIKOptions& options() const;
  int n_joints() const;

  // Solve for `target` (tip pose in the chain's base frame) from `q_init` (n finite values within the limits).
  // Returns true and writes q_out on success; returns false (q_out = q_init) when no solution was found in time.
  // Throws InputError on invalid input (non-finite or non-rigid target, wrong size or out-of-limits q_init).
  bool solve(const Eigen::Isometry3d& target, const Eigen::Ref<const Eigen::VectorXd>& q_init,
             Eigen::VectorXd& q_out) const;
  // The same with per-call tolerances instead of options().bounds.
  bool solve(const Eigen::Isometry3d& target, const Eigen::Ref<const Eigen::VectorXd>& q_init,
             const Vector6d& bounds, Eigen::VectorXd& q_out) const;
  // Full control: per-call options (which must be valid) and algorithm; returns details.
  IKResult solve_ex(const Eigen::Isometry3d& target, const Eigen::Ref<const Eigen::VectorXd>& q_init,
                    const TracIKOptions& options, IKAlgorithm algorithm = IKAlgorithm::TracIK) const;

  // Solve many targets across core_threads() threads (core_threads.hpp: the calling thread and the worker pool's).
  // q_inits is n x T (one column per target). Each target gets the full timeout; its two solvers run interleaved in
  // one thread (the seeded schedule above, on the clock when unseeded). With a seed, target k uses a generator derived from (seed, k), so results do not depend on
  // which thread solved it. q_out is resized to n x T; ok to T. `streams` (T values, or nullptr for 0..T-1): the
  // stream of each target in place of its index, so that a subset of a batch solved on its own gives, target for
  // target, what the whole batch gives.
  void solve_many(const std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>>& targets,
                  const Eigen::Ref<const Eigen::MatrixXd>& q_inits, Eigen::MatrixXd& q_out,
                  std::vector<bool>& ok, const std::vector<std::uint64_t>* streams = nullptr) const;

  // The threads a batch (solve_many) may use beside the bound core_threads() sets: the machine's hardware threads.
  // (Threads come from the core's one worker pool, worker_pool.hpp.)
  int n_workers() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Throws InputError unless `target` is finite with an orthonormal, right-handed rotation.
void check_pose(const Eigen::Isometry3d& target, const char* what = "target");

// KDL's own ChainIkSolverPos_NR_JL (pseudo-inverse Newton-Raphson with joint limits, no restarts), the
// paper's "KDL", for the benchmark: iterates from q_init until KDL reports convergence at `epsilon` (its own
// per-component twist test) or `timeout` seconds have passed. Returns true on convergence.
bool kdl_nr_jl_ik(const ChainModel& model, const Eigen::Isometry3d& target,
                  const Eigen::Ref<const Eigen::VectorXd>& q_init, Eigen::VectorXd& q_out, double timeout = 0.005,
                  double epsilon = 1e-5);

}  // namespace snakehead
