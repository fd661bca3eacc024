// The clouds the reconstruction harnesses build from the fuzzer's bytes: float32 or
// float64, a stride with padding (or 0: packed), up to `max_points` points, each either raw
// bit patterns (NaN, Inf, denormals) or snapped to a coarse grid (degenerate layers),
// optionally repeating an earlier point. The buffer ends exactly after the last point's z,
// so any overrun trips AddressSanitizer.
#ifndef STRATMESH_FUZZ_CLOUD_H
#define STRATMESH_FUZZ_CLOUD_H

#include "fuzz_common.h"
#include "stratmesh.h"

#include <cmath>
#include <cstring>
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

}  // namespace stratmesh_fuzz

#endif  // STRATMESH_FUZZ_CLOUD_H
