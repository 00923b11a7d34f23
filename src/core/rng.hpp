#pragma once
/// The project's own random numbers: the same bits on every standard library.
/// xoshiro256** (Blackman & Vigna 2018) seeded through SplitMix64.
#include <cmath>
#include <cstdint>
#include <string_view>

namespace clumpforge {

class Rng {
 public:
  /// A generator for `seed`; `stream` selects an independent substream, so work item i
  /// uses Rng(seed, i) and 1 or N threads give the same numbers.
  explicit Rng(std::uint64_t seed, std::uint64_t stream = 0) {
    std::uint64_t x = seed ^ (0x9E3779B97F4A7C15ULL * (stream + 1));
    for (auto& word : state_) word = splitmix64(x);
  }

  std::uint64_t next_u64() {
    const std::uint64_t result = rotl(state_[1] * 5, 7) * 9;
    const std::uint64_t t = state_[1] << 17;
    state_[2] ^= state_[0];
    state_[3] ^= state_[1];
    state_[1] ^= state_[2];
    state_[0] ^= state_[3];
    state_[2] ^= t;
    state_[3] = rotl(state_[3], 45);
    return result;
  }
  /// Uniform in [0, 1), 53 random bits.
  double uniform() { return static_cast<double>(next_u64() >> 11) * 0x1.0p-53; }
  double uniform(double low, double high) { return low + (high - low) * uniform(); }
  /// Uniform integer in [0, n).
  std::uint64_t below(std::uint64_t n) { return n == 0 ? 0 : next_u64() % n; }
  /// Standard normal by Box-Muller (no cached second value: stateless apart from the stream).
  double normal() {
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * 3.141592653589793 * u2);
  }
  double normal(double mean, double sigma) { return mean + sigma * normal(); }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  static std::uint64_t splitmix64(std::uint64_t& x) {
    std::uint64_t z = (x += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  std::uint64_t state_[4];
};

/// A seed made from a run's seed and a work item's identity (a name, a digest): the same on
/// every rank, thread and order, different for every item.
inline std::uint64_t seed_for(std::uint64_t seed, std::string_view identity) {
  std::uint64_t h = 1469598103934665603ULL ^ seed;  // FNV-1a, then mixed
  for (unsigned char c : identity) h = (h ^ c) * 1099511628211ULL;
  return Rng(h).next_u64();
}

}  // namespace clumpforge
