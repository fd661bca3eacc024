// Shared helpers for the stratmesh fuzz harnesses: a byte reader that never runs out
// (missing bytes read as zero), a loud failure for a broken invariant, and the random
// numbers of the structure-aware mutators.
//
// The harnesses are built two ways: with clang's libFuzzer (fuzz/CMakeLists.txt) and, with
// any compiler, against fuzz/replay/replay_main.cpp, which runs each file of a corpus
// directory once (fuzz/replay/CMakeLists.txt, ctest fuzz_replay_<harness>).
#ifndef STRATMESH_FUZZ_COMMON_H
#define STRATMESH_FUZZ_COMMON_H

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace stratmesh_fuzz {

// A broken invariant: print it and abort, which libFuzzer reports as a crash (and saves
// the input). The replay driver (STRATMESH_FUZZ_REPLAY) exits with status 1 instead, so
// that ctest can also register known-bug reproducers as expected to fail.
[[noreturn]] inline void fail(const char* what, const char* detail = nullptr) {
    std::fprintf(stderr, "fuzz invariant failed: %s%s%s\n", what, detail ? ": " : "",
                 detail ? detail : "");
    std::fflush(stderr);
#if defined(STRATMESH_FUZZ_REPLAY)
    std::_Exit(1);
#else
    std::abort();
#endif
}

#define STRATMESH_FUZZ_CHECK(cond, what)                                                     \
    do {                                                                                   \
        if (!(cond)) ::stratmesh_fuzz::fail(what, #cond);                                  \
    } while (0)

class Bytes {
public:
    Bytes(const uint8_t* data, size_t size) : data_(data), size_(size) {}

    size_t remaining() const { return size_ - pos_; }
    size_t position() const { return pos_; }

    uint8_t u8() { return pos_ < size_ ? data_[pos_++] : 0; }
    // (Each read is its own statement: the order in which operands or function arguments
    // are evaluated is unspecified, and differs between GCC and Clang.)
    uint16_t u16() {
        uint16_t lo = u8();
        uint16_t hi = u8();
        return static_cast<uint16_t>(lo | (hi << 8));
    }
    uint32_t u32() {
        uint32_t v = 0;
        for (int k = 0; k < 4; ++k) v |= static_cast<uint32_t>(u8()) << (8 * k);
        return v;
    }
    uint64_t u64() {
        uint64_t v = 0;
        for (int k = 0; k < 8; ++k) v |= static_cast<uint64_t>(u8()) << (8 * k);
        return v;
    }
    double raw_double() {
        uint64_t bits = u64();
        double v;
        std::memcpy(&v, &bits, sizeof v);
        return v;
    }
    float raw_float() {
        uint32_t bits = u32();
        float v;
        std::memcpy(&v, &bits, sizeof v);
        return v;
    }
    // An integer in [0, n), n > 0.
    uint32_t below(uint32_t n) { return n ? static_cast<uint32_t>(u16() % n) : 0u; }
    // A signed integer in [-range, range].
    int32_t centered(uint32_t range) {
        return static_cast<int32_t>(below(2 * range + 1)) - static_cast<int32_t>(range);
    }

private:
    const uint8_t* data_;
    size_t size_;
    size_t pos_ = 0;
};

// The custom mutators' random numbers (xorshift), from libFuzzer's seed for the call.
class Random {
public:
    explicit Random(unsigned seed) : state_(seed * 0x9E3779B97F4A7C15ull + 1) {}
    uint64_t next() {
        state_ ^= state_ << 13;
        state_ ^= state_ >> 7;
        state_ ^= state_ << 17;
        return state_;
    }
    // An integer in [0, n); 0 for n = 0.
    size_t below(size_t n) { return n ? static_cast<size_t>(next() % n) : 0; }
    // An integer in [lo, hi].
    int64_t between(int64_t lo, int64_t hi) {
        return lo + static_cast<int64_t>(below(static_cast<size_t>(hi - lo) + 1));
    }
    // A double in [0, 1).
    double uniform() { return static_cast<double>(next() >> 11) * 0x1p-53; }

private:
    uint64_t state_;
};

}  // namespace stratmesh_fuzz

#endif
