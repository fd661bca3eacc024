// bench_random.h - the benchmark's deterministic random numbers.
//
// SplitMix64, written out here so that the inputs are the same bit for bit with every
// standard library (std::uniform_real_distribution and std::normal_distribution are not
// specified exactly and differ between implementations).

#ifndef STRATMESH_BENCH_RANDOM_H
#define STRATMESH_BENCH_RANDOM_H

#include <cmath>
#include <cstddef>
#include <cstdint>

namespace bench {

class Random {
public:
    explicit Random(uint64_t seed) : state_(seed) {}

    uint64_t next() {
        state_ += 0x9E3779B97F4A7C15ull;
        uint64_t z = state_;
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }

    // Uniform in [0, 1), a multiple of 2^-53.
    double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

    // Uniform in (0, 1], safe for log().
    double uniform_open_at_zero() {
        return static_cast<double>((next() >> 11) + 1) * 0x1.0p-53;
    }

    // Uniform in [lo, hi).
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

    // Uniform integer in [0, bound), bound > 0 (the modulo bias is irrelevant here).
    size_t below(size_t bound) { return static_cast<size_t>(next() % bound); }

    // A pair of independent standard normal deviates (Box-Muller).
    void normal_pair(double& a, double& b) {
        const double two_pi = 6.283185307179586476925286766559;
        double radius = std::sqrt(-2.0 * std::log(uniform_open_at_zero()));
        double angle = two_pi * uniform();
        a = radius * std::cos(angle);
        b = radius * std::sin(angle);
    }

private:
    uint64_t state_;
};

}  // namespace bench

#endif  // STRATMESH_BENCH_RANDOM_H
