// TOPP-RA (Pham and Pham 2018, "A New Approach to Time-Optimal Path Parameterization based on Reachability
// Analysis"): the fastest timing of a path s in [s_0, s_N] under linear constraints on its squared speed x = s'^2
// and its acceleration u = s'' at the gridpoints s_0 < ... < s_N.
//
// Stage i (0 <= i < N) holds u_i (constant between s_i and s_{i+1}), so x_{i+1} = x_i + 2 delta_i u_i with
// delta_i = s_{i+1} - s_i. Its constraints are m rows A_i u + B_i x <= C_i (the caller's discretization: with
// toppra's "interpolation" one, the constraints of gridpoint i at (u, x) and those of gridpoint i+1 at
// (u, x + 2 delta_i u)), u in [u_lo_i, u_hi_i] and x in [x_lo_i, x_hi_i] (and x >= 0 always).
//
// The backward pass computes the controllable sets K_i = [K_i^lo, K_i^hi]: the x_i from which x_N = x_end can be
// reached, K_N = {x_end}, each K_i by two 2-D LPs over (u, x): max x and min x subject to stage i's rows and
// x + 2 delta_i u in K_{i+1}. The forward pass starts at x_0 = x_start and takes, stage by stage, the largest u
// that keeps x_{i+1} in K_{i+1} (a 1-D LP, x_i fixed). Both passes keep toppra's safeguards against round-off
// (the same constants; see cpp/topp_ra.cpp).
//
// Each 2-D LP (its rows normalised to unit normals, so that the tolerances are lengths whatever the rows' scale)
// is solved exactly by Seidel's randomized incremental algorithm: the rows are added one at a time in
// a random order (one permutation per call, from a fixed seed: the results are reproducible), and whenever the
// optimum so far breaks the new row, the optimum moves onto that row's line, a 1-D LP over the rows before it and
// the bounds; expected O(m) per LP. As toppra's seidel solver does, the rows active at the previous optimum of the
// same kind (max x or min x) are added first (a warm start: usually no row after them moves the optimum).
//
// Pure C++; no globals: safe to call from many threads at once.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace snakehead {

using RowMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using RowMatrixX2d = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;

// ------------------------------------------------------------------------------------------------------------------
// The 2-D LP
// ------------------------------------------------------------------------------------------------------------------
// A half-plane a u + b x <= c.
struct HalfPlane {
  double a, b, c;
};

// The box's sides as "active" indices (rows are >= 0): u >= lo, u <= hi, x >= lo, x <= hi.
enum Lp2dBound : int { kULow = -1, kUHigh = -2, kXLow = -3, kXHigh = -4 };

struct Lp2dSolution {
  bool feasible = false;
  double u = 0.0, x = 0.0;
  // The two constraints that define the optimum (row indices, or Lp2dBound values); a warm start for the next LP.
  int active[2] = {kULow, kXLow};
};

// The half-plane with a unit normal (a, b) (the same set; a row 0 u + 0 x <= c as it is).
HalfPlane normalized(const HalfPlane& h);

// maximise v_u u + v_x x subject to rows[k] (k < m) and lo <= (u, x) <= hi (finite; lo > hi: infeasible).
// order: the order in which the rows are added (a permutation of 0..m-1; nullptr: 0, 1, ..., m-1). The rows should
// have unit normals (normalized()): the tolerances are toppra's, as lengths in the (u, x) plane then: a row counts
// as kept when broken by less than 1e-10, two rows as parallel when the sine of their angle is below 1e-10 (then
// infeasible only when one is broken by more than 1e-8 all along the other). Where the optimum is not unique, the
// result is one of the optimal vertices (which one depends on the order).
Lp2dSolution solve_lp2d(double v_u, double v_x, const HalfPlane* rows, int m, const double lo[2], const double hi[2],
                        const int* order = nullptr);

// maximise u subject to rows[k] at x (rows with |a| <= 1e-10 do not bound u and are left out, as toppra does) and
// u_lo <= u <= u_hi. False when infeasible.
bool max_u_at(double x, const HalfPlane* rows, int m, double u_lo, double u_hi, double* u);

// ------------------------------------------------------------------------------------------------------------------
// TOPP-RA
// ------------------------------------------------------------------------------------------------------------------
enum class ToppRaStatus {
  kFeasible = 0,
  kUncontrollable = 1,  // the backward pass found an empty K_i (at failed_at): no timing follows the path from there
  kStartOutside = 2,    // x_start is not in K_0 (failed_at = 0)
  kForwardFailed = 3,   // round-off: the forward pass found no u at failed_at although x_i was in K_i
};

struct ToppRaResult {
  ToppRaStatus status = ToppRaStatus::kFeasible;
  int failed_at = -1;     // the gridpoint where the status says it failed; -1 when feasible
  std::vector<double> x;  // N+1 squared path speeds (NaN from where the forward pass did not reach)
  std::vector<double> u;  // N path accelerations as realised: (x_{i+1} - x_i) / (2 delta_i) (NaN likewise)
  RowMatrixX2d K;         // N+1 controllable sets [lo, hi] (NaN at failed_at and before it when uncontrollable)
  int lp_count = 0;       // 2-D and 1-D LPs solved (for benchmarks)
};

// TOPP-RA over grid (N+1, strictly increasing, N >= 1) with stage rows A, B, C (N x m each: A_i u + B_i x <= C_i,
// finite), u_bounds (N x 2) per stage, x_bounds (N+1 x 2) per gridpoint (not NaN; +-inf allowed, taken as +-1e8 as
// toppra does; lo > hi: no x there), from x_0 = x_start to x_N = x_end (finite, >= 0; outside x_bounds at N:
// uncontrollable at N). Throws InputError on a malformed input (sizes, NaN, a grid not increasing).
ToppRaResult topp_ra(const Eigen::Ref<const Eigen::VectorXd>& grid, const Eigen::Ref<const RowMatrixXd>& A,
                     const Eigen::Ref<const RowMatrixXd>& B, const Eigen::Ref<const RowMatrixXd>& C,
                     const Eigen::Ref<const RowMatrixX2d>& u_bounds, const Eigen::Ref<const RowMatrixX2d>& x_bounds,
                     double x_start, double x_end);

// topp_ra over the constraints of the gridpoints themselves, in TOPP-RA's canonical form P u + Q x <= R (N+1 x m
// each, finite) and x <= x_max (N+1; not NaN, inf for none), discretized here as toppra's "interpolation"
// discretization does it (stage i: gridpoint i's rows at (u, x), gridpoint i+1's at (u, x + 2 delta_i u)), with u
// free and x >= 0: the same result, to the bit, as topp_ra given the stage matrices retiming._topp.interpolated makes
// (A = [P_i, P_{i+1} + 2 delta_i Q_{i+1}], B = [Q_i, Q_{i+1}], C = [R_i, R_{i+1}]), without making them: each stage's
// rows are made where a pass uses them.
ToppRaResult topp_ra_canonical(const Eigen::Ref<const Eigen::VectorXd>& grid, const Eigen::Ref<const RowMatrixXd>& P,
                               const Eigen::Ref<const RowMatrixXd>& Q, const Eigen::Ref<const RowMatrixXd>& R,
                               const Eigen::Ref<const Eigen::VectorXd>& x_max, double x_start, double x_end);

}  // namespace snakehead
