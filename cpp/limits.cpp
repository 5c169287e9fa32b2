#include "snakehead/limits.hpp"

#include <cmath>
#include <cstdio>

#include "snakehead/model.hpp"

namespace snakehead {

std::string number_text(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", x);
  return buf;
}

void check_timeout(double seconds, const std::string& field) {
  if (!(seconds > 0) || !std::isfinite(seconds))
    throw InputError(field + " must be a positive finite number of seconds, got " + number_text(seconds));
  if (seconds > limits::kMaxTimeoutSeconds)
    throw InputError(field + " must be at most " + number_text(limits::kMaxTimeoutSeconds) + " s (one day), got " +
                     number_text(seconds));
}

std::chrono::steady_clock::time_point deadline_after(std::chrono::steady_clock::time_point start, double seconds) {
  using Clock = std::chrono::steady_clock;
  if (!(seconds > 0)) return start;  // also NaN: give up at once rather than never
  // Seconds left before the clock's largest time point; half of it keeps the conversion to integer ticks
  // clear of rounding at the edge (the margin is still ~146 years).
  const double seconds_left = std::chrono::duration<double>(Clock::time_point::max() - start).count();
  if (seconds >= 0.5 * seconds_left) return Clock::time_point::max();
  return start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

}  // namespace snakehead
