// The core's random numbers, one implementation for every user (TRAC-IK's restarts, the workspace sweep's point
// cloud, guesses and IK seeds): SplitMix64 (Steele, Lea and Flood, "Fast splittable pseudorandom number generators",
// OOPSLA 2014) to mix a seed and an index into independent stream seeds and as a generator of 8 bytes of state, and
// our own mapping to uniform doubles and joint configurations (std::uniform_real_distribution's algorithm is
// unspecified: seeded results must not depend on the standard library).
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <limits>

#include "snakehead/model.hpp"

namespace snakehead {

// SplitMix64's output function of state x + golden gamma: a bijection of 64-bit words that mixes every bit.
constexpr std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

// The seed of stream `index` of the family `salt` under `seed`: well mixed, independent of the other streams.
constexpr std::uint64_t stream_seed(std::uint64_t seed, std::uint64_t salt, std::uint64_t index) {
  return splitmix64(splitmix64(seed ^ splitmix64(salt)) ^ index);
}

// SplitMix64 as a generator (a UniformRandomBitGenerator): seeding one per call costs nothing (a Mersenne twister's
// 2.5 kB state takes a noticeable share of a 20 us IK call), and its statistics are ample for restarts.
class SplitMix64 {
 public:
  using result_type = std::uint64_t;
  void seed(std::uint64_t s) { state_ = s; }
  std::uint64_t operator()() {
    const std::uint64_t z = splitmix64(state_);
    state_ += 0x9E3779B97F4A7C15ULL;
    return z;
  }
  static constexpr std::uint64_t min() { return 0; }
  static constexpr std::uint64_t max() { return std::numeric_limits<std::uint64_t>::max(); }

 private:
  std::uint64_t state_ = 0;
};

// This thread's generator, seeded once from the operating system (std::random_device): the seeds of unseeded calls.
SplitMix64& thread_generator();

// Uniform in [0, 1) from the top 53 bits of a 64-bit generator's next word (SplitMix64, std::mt19937_64).
template <class Generator>
double unit_uniform(Generator& g) {
  static_assert(Generator::max() == std::numeric_limits<std::uint64_t>::max() && Generator::min() == 0,
                "unit_uniform needs a generator of 64-bit words");
  return static_cast<double>(g() >> 11) * 0x1.0p-53;
}

// The box random configurations are drawn from: each joint's limits, [-pi, pi] (rad) for a joint without
// (continuous).
struct SamplingRange {
  explicit SamplingRange(const ChainModel& model);
  Eigen::VectorXd lo, hi;

  // A configuration drawn uniformly from the box into q (resized): lo + (hi - lo) u joint by joint, in order.
  template <class Generator>
  void draw(Generator& g, Eigen::VectorXd& q) const {
    q.resize(lo.size());
    for (Eigen::Index i = 0; i < lo.size(); ++i) q[i] = lo[i] + (hi[i] - lo[i]) * unit_uniform(g);
  }
};

}  // namespace snakehead
