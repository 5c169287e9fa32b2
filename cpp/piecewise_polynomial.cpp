#include "snakehead/piecewise_polynomial.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "snakehead/model.hpp"
#include "snakehead/parallel_for.hpp"

namespace snakehead {

namespace {

// Points below which another thread costs more than it saves (a quintic of 16 columns takes ~40 ns a point, a thread
// ~0.1 ms to start and join: 7000 points ran faster on one thread than on two).
constexpr long kPointsPerThread = 16384;

// The interval of x: the last j with breaks[j] <= x, within [0, m - 1] (PPoly's find_interval for strictly increasing
// breaks, extrapolating: below the first break the first interval, at or above the last break the last).
long interval_of(const double* breaks, long m, double x) {
  const long j = static_cast<long>(std::upper_bound(breaks, breaks + m + 1, x) - breaks) - 1;
  return std::clamp(j, 0L, m - 1);
}

}  // namespace

void evaluate_piecewise_polynomial(const double* c, long k, long m, long n, const double* breaks, const double* points,
                                   long N, double* out) {
  if (k < 1 || m < 1 || n < 0 || N < 0)
    throw InputError("piecewise polynomial: at least one coefficient and one interval are needed");
  for (long j = 0; j <= m; ++j)
    if (!std::isfinite(breaks[j]) || (j > 0 && !(breaks[j] > breaks[j - 1])))
      throw InputError("piecewise polynomial: the breakpoints must be finite and increase strictly");
  for (long p = 0; p < N; ++p)
    if (!std::isfinite(points[p])) throw InputError("piecewise polynomial: the points must be finite");
  parallel_for(N, kPointsPerThread, [&](long begin, long end) {
    std::vector<double> power(static_cast<std::size_t>(k));
    for (long p = begin; p < end; ++p) {
      const long j = interval_of(breaks, m, points[p]);
      const double s = points[p] - breaks[j];
      // PPoly's evaluate_poly1 at dx = 0, for every column at once: the terms from the lowest power up, each c * s^i
      // (its prefactor, 1, is exact), the power built by repeated multiplication; a column's sum in the same order
      power[0] = 1.0;
      for (long i = 1; i < k; ++i) power[i] = power[i - 1] * s;
      double* row = out + p * n;
      std::fill(row, row + n, 0.0);
      for (long i = 0; i < k; ++i) {
        const double* ci = c + ((k - 1 - i) * m + j) * n;
        for (long l = 0; l < n; ++l) row[l] = row[l] + ci[l] * power[i];
      }
    }
  });
}

}  // namespace snakehead
