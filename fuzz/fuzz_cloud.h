// The clouds the reconstruction harnesses build from the fuzzer's bytes: float32 or
// float64, a stride with padding (or 0: packed), up to `max_points` points, each either raw
// bit patterns (NaN, Inf, denormals) or snapped to a coarse grid (degenerate layers),
// optionally repeating an earlier point. The buffer ends exactly after the last point's z,
// so any overrun trips AddressSanitizer. write_cloud() gives the bytes of a given cloud,
// for the structure-aware mutator (fuzz_cloud_mutator.h).
#ifndef STRATMESH_FUZZ_CLOUD_H
#define STRATMESH_FUZZ_CLOUD_H

#include "fuzz_common.h"
#include "stratmesh.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <unordered_map>
#include <vector>

namespace stratmesh_fuzz {

struct FuzzCloud {
    std::vector<double> xyz;            // the points as the library reads them, as doubles
    std::vector<unsigned char> buffer;  // the points as the library is given them
    size_t n = 0;
    size_t stride = 0;                  // 0: packed
    size_t step = 0;                    // bytes from one point to the next
    bool f32 = false;
    double grid = 1;                    // the grid's spacing
    uint32_t grid_range = 1;            // grid coordinates run over [-range, range]

    stratmesh::Cloud cloud() const {
        return {n ? buffer.data() : nullptr, n, stride,
                f32 ? stratmesh::Scalar::float32 : stratmesh::Scalar::float64};
    }

    // The first `count` points (at most n), in a buffer of their exact size.
    FuzzCloud first(size_t count) const {
        FuzzCloud c = *this;
        c.n = count < n ? count : n;
        c.xyz.assign(xyz.begin(), xyz.begin() + static_cast<std::ptrdiff_t>(3 * c.n));
        const size_t bytes = c.n ? (c.n - 1) * step + 3 * (f32 ? 4 : 8) : 0;
        c.buffer = std::vector<unsigned char>(buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(bytes));
        return c;
    }
};

inline FuzzCloud read_cloud(Bytes& in, uint32_t max_points) {
    FuzzCloud c;
    const uint8_t cfg = in.u8();
    c.f32 = cfg & 1;
    const size_t scalar_size = c.f32 ? 4 : 8;
    const size_t pad = (cfg >> 1) & 7;  // 0: packed (stride 0)
    c.stride = pad ? 3 * scalar_size + pad : 0;
    c.step = c.stride ? c.stride : 3 * scalar_size;
    const uint8_t point_mode = in.u8();  // 0..63 grid-ish, 64..127 mixed per point, else raw
    c.n = in.below(max_points);
    c.grid = std::ldexp(1.0, in.centered(8));
    c.grid_range = 1u + in.below(24);
    const size_t n = c.n;
    c.xyz.assign(3 * n, 0);
    c.buffer.assign(n ? (n - 1) * c.step + 3 * scalar_size : 0, 0);
    for (size_t i = 0; i < n; ++i) {
        double* xyz = c.xyz.data();
        uint8_t kind = point_mode < 64 ? 0 : point_mode < 128 ? in.u8() % 4 : 3;
        if (kind == 1 && i > 0) {  // repeat an earlier point
            size_t j = in.below(static_cast<uint32_t>(i));
            std::memcpy(&xyz[3 * i], &xyz[3 * j], 3 * sizeof(double));
        } else if (kind == 3) {  // raw bits
            for (size_t k = 0; k < 3; ++k) {
                double v = c.f32 ? static_cast<double>(in.raw_float()) : in.raw_double();
                xyz[3 * i + k] = v;
            }
        } else {  // a coarse grid on (and inside) a cylinder-ish column
            int32_t a = in.centered(c.grid_range), b = in.centered(c.grid_range);
            int32_t h = in.centered(4 * c.grid_range);
            xyz[3 * i] = a * c.grid;
            xyz[3 * i + 1] = b * c.grid;
            xyz[3 * i + 2] = h * c.grid;
        }
        unsigned char* p = c.buffer.data() + i * c.step;
        for (size_t k = 0; k < 3; ++k) {
            if (c.f32) {
                float v = static_cast<float>(xyz[3 * i + k]);
                xyz[3 * i + k] = static_cast<double>(v);
                std::memcpy(p + 4 * k, &v, 4);
            } else {
                std::memcpy(p + 8 * k, &xyz[3 * i + k], 8);
            }
        }
        if (pad && i + 1 < n) std::memset(p + 3 * scalar_size, 0xEE, pad);  // NaN-ish padding
    }
    return c;
}

// A cloud as write_cloud() writes it: the header's fields and every point's coordinates.
struct CloudSpec {
    bool f32 = false;
    uint32_t pad = 0;           // bytes after each point but the last, 0 to 7 (0: packed)
    int32_t grid_exponent = 0;  // the grid's spacing is 2^e, e in [-8, 8] (the options' cuts use it)
    uint32_t grid_range = 1;    // 1 to 24
    std::vector<double> xyz;

    size_t count() const { return xyz.size() / 3; }
};

// x as a float32 cloud holds it: rounded to float, beyond float's range infinite.
inline double as_float(double x) {
    const double largest = static_cast<double>(std::numeric_limits<float>::max());
    if (x > largest) return HUGE_VAL;
    if (x < -largest) return -HUGE_VAL;
    return static_cast<double>(static_cast<float>(x));
}

// The spec of a cloud read_cloud() gave.
inline CloudSpec spec_of(const FuzzCloud& c) {
    CloudSpec s;
    s.f32 = c.f32;
    s.pad = c.stride ? static_cast<uint32_t>(c.stride - 3 * (c.f32 ? 4 : 8)) : 0;
    s.grid_exponent = std::ilogb(c.grid);
    s.grid_range = c.grid_range;
    s.xyz = c.xyz;
    return s;
}

// Makes every coordinate one that the spec's scalar holds, so that the cloud reads back
// exactly as given.
inline void settle(CloudSpec& spec) {
    if (spec.f32)
        for (double& v : spec.xyz) v = as_float(v);
}

inline void put_u16(std::vector<uint8_t>& out, uint32_t v) {
    out.push_back(static_cast<uint8_t>(v & 0xFF));
    out.push_back(static_cast<uint8_t>((v >> 8) & 0xFF));
}

// Appends the bytes that read_cloud() reads as the settled `spec`, whose point count must
// be below read_cloud()'s max_points: per-point kinds (point_mode 64), each point either its
// raw bits or, where it repeats an earlier point bit for bit, that point's index.
inline void write_cloud(const CloudSpec& spec, std::vector<uint8_t>& out) {
    const size_t n = spec.count();
    out.push_back(static_cast<uint8_t>((spec.f32 ? 1 : 0) | (spec.pad & 7) << 1));
    out.push_back(64);
    put_u16(out, static_cast<uint32_t>(n));
    put_u16(out, static_cast<uint32_t>(spec.grid_exponent + 8));
    put_u16(out, spec.grid_range - 1);
    std::unordered_map<uint64_t, uint32_t> seen;  // a hash of a point's bits: its first index
    for (size_t i = 0; i < n; ++i) {
        const double* p = &spec.xyz[3 * i];
        uint64_t key = 1469598103934665603ull;
        for (size_t k = 0; k < 3; ++k) {
            uint64_t bits;
            std::memcpy(&bits, &p[k], 8);
            key = (key ^ bits) * 1099511628211ull;
        }
        const auto found = seen.emplace(key, static_cast<uint32_t>(i));
        if (!found.second && std::memcmp(&spec.xyz[3 * found.first->second], p, 3 * sizeof(double)) == 0) {
            out.push_back(1);
            put_u16(out, found.first->second);
            continue;
        }
        out.push_back(3);
        for (size_t k = 0; k < 3; ++k) {
            unsigned char raw[8];
            if (spec.f32) {
                const float f = static_cast<float>(p[k]);
                std::memcpy(raw, &f, 4);
            } else {
                std::memcpy(raw, &p[k], 8);
            }
            out.insert(out.end(), raw, raw + (spec.f32 ? 4 : 8));
        }
    }
}

}  // namespace stratmesh_fuzz

#endif  // STRATMESH_FUZZ_CLOUD_H
