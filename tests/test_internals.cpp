// Internal functions whose fast paths must answer as the plain way does, bit for bit:
// the frame's height range from the extremes, the layer of a height; and the one place
// that hands jobs to the caller's runner. This suite compiles the implementation itself,
// to reach them.
#define STRATMESH_IMPLEMENTATION
#include "stratmesh.h"

#include <doctest/doctest.h>

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

using stratmesh::Axis;
using stratmesh::Cloud;
using stratmesh::Options;
using stratmesh::Scalar;
using stratmesh::Status;

#if !defined(STRATMESH_SMALL_CODE)  // which keeps no extremes in the frame (kFastLoops)
TEST_CASE("internals: the height range from a coordinate axis's extremes equals the pass") {
    std::mt19937_64 random(20261202);
    std::uniform_real_distribution<double> unit(-1, 1);
    for (int trial = 0; trial < 200; ++trial) {
        // Offsets and sizes from tiny to huge, float and double, some invalid points, and
        // now and then a given origin far away.
        const double offset = std::ldexp(unit(random), static_cast<int>(random() % 200) - 100);
        const double size = std::ldexp(1.0, static_cast<int>(random() % 120) - 60);
        const bool as_float = trial % 3 == 0;
        const size_t count = 3 + random() % 300;
        std::vector<double> xyz(3 * count);
        std::vector<float> xyz_float(3 * count);
        for (size_t i = 0; i < 3 * count; ++i) {
            xyz[i] = offset + size * unit(random);
            if (random() % 50 == 0) xyz[i] = std::numeric_limits<double>::quiet_NaN();
            xyz_float[i] = static_cast<float>(xyz[i]);
        }
        const Cloud cloud = {as_float ? static_cast<const void*>(xyz_float.data()) : xyz.data(),
                             count, 0, as_float ? Scalar::float32 : Scalar::float64};
        const stratmesh::detail::CloudReader reader = stratmesh::detail::reader_of(cloud);
        for (Axis axis : {Axis::x, Axis::y, Axis::z, Axis::direction}) {
            Options options = {};
            options.axis = axis;
            options.direction[0] = 0;
            options.direction[1] = -0.0;
            options.direction[2] = 3;  // normalised to exactly (0, 0, 1) or (0, -0, 1)
            if (trial % 7 == 0) {
                options.flags |= stratmesh::origin_given;
                for (double& o : options.origin) o = offset + 1e6 * size * unit(random);
            }
            stratmesh::detail::Frame frame;
            const stratmesh::detail::CloudSums sums = stratmesh::detail::sum_cloud(reader, count);
            REQUIRE(stratmesh::detail::choose_frame(sums, options, frame) == Status::ok);
            double lo = DBL_MAX, hi = -DBL_MAX, pass_lo = DBL_MAX, pass_hi = -DBL_MAX;
            stratmesh::detail::height_range(reader, count, frame, &pass_lo, &pass_hi);
            INFO("trial " << trial << ", offset " << offset << ", size " << size);
            if (stratmesh::detail::height_range_from_extremes(frame, &lo, &hi)) {
                CHECK(!frame.halved);
                CHECK(std::memcmp(&lo, &pass_lo, sizeof lo) == 0);
                CHECK(std::memcmp(&hi, &pass_hi, sizeof hi) == 0);
            } else {
                CHECK(frame.halved);  // every axis here is a coordinate axis
            }
        }
    }
}

#endif

TEST_CASE("internals: layer_of finds the same layer as a scan of the bounds") {
    std::mt19937_64 random(7);
    std::uniform_real_distribution<double> unit(0, 1);
    for (int trial = 0; trial < 300; ++trial) {
        // Equal layers (the guess's case), uneven ones, and one layer.
        const uint32_t count = 1 + static_cast<uint32_t>(random() % (trial % 5 == 0 ? 1 : 40));
        std::vector<double> bounds(count + 1);
        const double lo = 1000 * (unit(random) - 0.5), height = std::ldexp(unit(random) + 0.1, trial % 9 - 4);
        for (uint32_t k = 0; k <= count; ++k) bounds[k] = lo + height * k / count;
        if (trial % 2 == 1)
            for (uint32_t k = 1; k < count; ++k)
                bounds[k] = bounds[k - 1] + (bounds[count] - bounds[k - 1]) * unit(random) / 2;
        const stratmesh::detail::LayerPlan plan = {bounds.data(), count, height * 0x1p-40};
        const double per_height = count / (bounds[count] - bounds[0]);
        for (int probe = 0; probe < 400; ++probe) {
            double h = bounds[0] + (bounds[count] - bounds[0]) * (1.2 * unit(random) - 0.1);
            if (probe % 4 == 0) {  // on a bound, or a hair either side of its tolerance
                const double b = bounds[random() % (count + 1)];
                const double steps[] = {0, -plan.tolerance, -plan.tolerance * 1.0000001,
                                        -plan.tolerance * 0.9999999};
                h = b + steps[random() % 4];
            }
            uint32_t expected = 0;
            for (uint32_t k = 1; k < count; ++k)
                if (h >= bounds[k] - plan.tolerance) expected = k;
            INFO("trial " << trial << ", " << count << " layers, h " << h);
            CHECK(stratmesh::detail::layer_of(plan, h, per_height) == expected);
        }
    }
}

TEST_CASE("internals: trailing_zeros counts as the loop over the bits does") {
    std::mt19937 random(11);
    for (int trial = 0; trial < 100000; ++trial) {
        // Random words with from 0 to 31 low bits cleared, and 0 itself.
        const uint32_t h = trial == 0 ? 0 : static_cast<uint32_t>(random()) << (trial % 32);
        const uint32_t limit = static_cast<uint32_t>(random() % 32);
        uint32_t expected = 0;
        while (expected < limit && (h & (1u << expected)) == 0) ++expected;
        INFO("h " << h << ", limit " << limit);
        CHECK(stratmesh::detail::trailing_zeros(h, limit) == expected);
    }
}

TEST_CASE("internals: exp_portable is within two ulp of exp, monotone, and clamped") {
    // Every 1e-4 over the range the unrolling uses, and the points of the table's steps
    // (k ln2 / 32), where the reduction changes j.
    double previous = 0;
    double worst = 0;
    for (long i = -640000; i <= 640000; ++i) {
        const double x = static_cast<double>(i) * 1e-4;
        const double e = stratmesh::detail::exp_portable(x);
        worst = std::fmax(worst, std::fabs(e - std::exp(x)) / std::exp(x));
        CHECK_MESSAGE(e >= previous, "x " << x);
        previous = e;
    }
    for (int k = -2954; k <= 2954; ++k) {
        const double x = k * 0.693147180559945309417 / 32;
        worst = std::fmax(worst, std::fabs(stratmesh::detail::exp_portable(x) - std::exp(x)) /
                                     std::exp(x));
    }
    INFO("worst relative error " << worst);
    CHECK(worst < 2 * DBL_EPSILON);
    // Beyond [-64, 64] and for NaN, the clamp's values.
    CHECK(stratmesh::detail::exp_portable(1e300) == stratmesh::detail::exp_portable(64));
    CHECK(stratmesh::detail::exp_portable(-1e300) == stratmesh::detail::exp_portable(-64));
    CHECK(stratmesh::detail::exp_portable(std::nan("")) == stratmesh::detail::exp_portable(-64));
    CHECK(stratmesh::detail::exp_portable(0) == 1);
}

namespace {

// Runners that break the contract in the ways JobRunner allows for; each counts its calls
// in *user.
void run_twice_and_strangers(void* user, uint32_t count, stratmesh::JobFunction job,
                             void* context) {
    ++*static_cast<int*>(user);
    job(context, count);
    for (int round = 0; round < 2; ++round)
        for (uint32_t i = 0; i < count; ++i) job(context, i);
    job(context, 0xFFFFFFFFu);
}

void run_even_jobs(void* user, uint32_t count, stratmesh::JobFunction job, void* context) {
    ++*static_cast<int*>(user);
    for (uint32_t i = 0; i < count; i += 2) job(context, i);
}

}  // namespace

TEST_CASE("internals: run_jobs runs each job once whatever the runner does, skipped ones after") {
    // Without parallel layers in the build the runner is never called: all run in order.
    const bool jobs = stratmesh::detail::kParallelLayers;
    const std::vector<uint32_t> in_order = {0, 1, 2, 3, 4, 5, 6};
    const std::vector<uint32_t> none = {};
    struct Case {
        const char* name;
        stratmesh::JobRunner runner;
        bool redo_skipped;
        std::vector<uint32_t> ran;  // the jobs run, in the order they ran
    };
    const Case cases[] = {
        {"no runner", nullptr, true, in_order},
        {"no runner, skipped jobs left undone", nullptr, false, none},
        {"each job twice, indices past the batch", run_twice_and_strangers, true, in_order},
        {"every other job", run_even_jobs, true,
         jobs ? std::vector<uint32_t>{0, 2, 4, 6, 1, 3, 5} : in_order},
        {"every other job, skipped jobs left undone", run_even_jobs, false,
         jobs ? std::vector<uint32_t>{0, 2, 4, 6} : none},
    };
    for (const Case& c : cases) {
        INFO(c.name);
        int runner_calls = 0;
        Options options = {};
        options.run_jobs = c.runner;
        options.jobs_user = &runner_calls;
        std::vector<uint32_t> ran;
        stratmesh::detail::run_jobs(options, 7, c.redo_skipped,
                                    [&ran](uint32_t k) { ran.push_back(k); });
        CHECK(ran == c.ran);
        CHECK(runner_calls == (c.runner && jobs ? 1 : 0));
    }
}
