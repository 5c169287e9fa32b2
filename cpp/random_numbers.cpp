#include "snakehead/random_numbers.hpp"

#include <cmath>
#include <random>

namespace snakehead {

SplitMix64& thread_generator() {
  thread_local SplitMix64 generator = [] {
    std::random_device rd;
    SplitMix64 g;
    g.seed((static_cast<std::uint64_t>(rd()) << 32) ^ rd());
    return g;
  }();
  return generator;
}

SamplingRange::SamplingRange(const ChainModel& model) : lo(model.n_joints()), hi(model.n_joints()) {
  for (int i = 0; i < model.n_joints(); ++i) {
    lo[i] = std::isfinite(model.lower()[i]) ? model.lower()[i] : -M_PI;
    hi[i] = std::isfinite(model.upper()[i]) ? model.upper()[i] : M_PI;
  }
}

}  // namespace snakehead
