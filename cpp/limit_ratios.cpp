#include "snakehead/limit_ratios.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "snakehead/model.hpp"
#include "snakehead/parallel_for.hpp"

namespace snakehead {

namespace {

// Samples below which another thread costs more than it saves (a sample of 16 joints takes ~0.1 us).
constexpr long kSamplesPerThread = 16384;

// numpy's (|x| / limit).max(axis=1) of one row.
double largest_ratio(const double* x, const double* limit, long n) {
  double worst = -std::numeric_limits<double>::infinity();
  for (long j = 0; j < n; ++j) worst = std::max(worst, std::abs(x[j]) / limit[j]);
  return worst;
}

}  // namespace

LimitRatios limit_ratios(long N, long n, long E, const double* qd, const double* qdd, const double* tau,
                         const double* Pdot, const double* Ldot, const double* com, const double* normal,
                         const double* offset, const double* velocity, const double* acceleration,
                         const double* torque, double Mg, double friction, double Mg_x, double Mg_y) {
  if (N < 0 || n < 1 || E < 1) throw InputError("limit_ratios: at least one joint and one polygon edge are needed");
  constexpr double kInf = std::numeric_limits<double>::infinity();
  LimitRatios r;
  for (auto* v : {&r.velocity, &r.acceleration, &r.torque, &r.friction, &r.zmp_margin})
    v->resize(static_cast<std::size_t>(N));
  parallel_for(N, kSamplesPerThread, [&](long begin, long end) {
    for (long k = begin; k < end; ++k) {
      r.velocity[k] = largest_ratio(qd + k * n, velocity, n);
      r.acceleration[k] = largest_ratio(qdd + k * n, acceleration, n);
      r.torque[k] = largest_ratio(tau + k * n, torque, n);
      const double normal_force = Mg + Pdot[3 * k + 2];
      const bool lifting = normal_force > 0.0;  // else the ground would have to pull: no ZMP
      const double safe = lifting ? normal_force : 1.0;
      const double x = (Mg * com[3 * k] - Ldot[3 * k + 1]) / safe;  // Eq. 39
      const double y = (Mg * com[3 * k + 1] + Ldot[3 * k]) / safe;  // Eq. 40
      double margin = kInf;
      for (long e = 0; e < E; ++e) {
        const double* u = normal + 2 * (k * E + e);
        // numpy's sum over the pair: from 0.0, in order
        margin = std::min(margin, ((0.0 + u[0] * x) + u[1] * y) - offset[k * E + e]);
      }
      r.zmp_margin[k] = lifting ? margin : -kInf;
      const double along_x = Pdot[3 * k] - Mg_x, along_y = Pdot[3 * k + 1] - Mg_y;  // the ground's push along it
      r.friction[k] = lifting ? std::hypot(along_x, along_y) / (friction * safe) : kInf;
    }
  });
  return r;
}

}  // namespace snakehead
