// A piecewise polynomial evaluated at many points, as scipy.interpolate.PPoly evaluates one (its call with nu = 0 and
// extrapolate = True): the same interval for each point, the same operations in the same order, so the same numbers
// to the bit. The retiming samples its joint paths (motion/interpolation.py's MonotoneQuintic) through it: thousands
// of points a plan, split over the core's threads.
#pragma once

namespace snakehead {

// Coefficients c (k x m x n, row-major: c[i][j][l] multiplies (x - breaks[j])^(k-1-i) in interval j of column l),
// breaks (m + 1, strictly increasing, finite), points (N, finite) -> out (N x n, row-major). A point below breaks[0]
// takes the first interval, one at or above breaks[m] the last. Throws InputError on k < 1, m < 1, breaks that do not
// increase strictly or are not finite, or a point that is not finite.
void evaluate_piecewise_polynomial(const double* c, long k, long m, long n, const double* breaks, const double* points,
                                   long N, double* out);

}  // namespace snakehead
