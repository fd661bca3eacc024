// fuzz_delaunay: stratmesh::delaunay_2d on point sets biased towards degeneracy (grids,
// exactly cocircular rings, lines, duplicates, raw bit patterns), checked with
// tests/support/delaunay_check.h: indices, counter-clockwise triangles, each directed edge
// once, the boundary equal to the convex hull, 2m - h - 2 triangles, duplicate_of, and, for
// n <= 64, empty circumcircles and the documented symbolic perturbation with the exact
// reference. Also: the status is one the documentation allows, info agrees with the
// result, a second run gives the same bits, and the output array ends where its
// allocation ends (an overrun trips AddressSanitizer).
#include "fuzz_common.h"

#include "stratmesh.h"
#include "support/delaunay_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace {

using stratmesh_fuzz::Bytes;

const int kRing[][2] = {{25, 0},  {24, 7},   {20, 15},  {15, 20},  {7, 24},
                        {0, 25},  {-7, 24},  {-15, 20}, {-20, 15}, {-24, 7},
                        {-25, 0}, {-24, -7}, {-20, -15}, {-15, -20}, {-7, -24},
                        {0, -25}, {7, -24},  {15, -20}, {20, -15}, {24, -7}};
const uint32_t kRingSize = sizeof kRing / sizeof kRing[0];

// Coordinates spanning more binary orders of magnitude than this are outside the
// predicates' exactness contract: the header promises exact signs while coordinates and
// their differences span at most 2^320; differences can sit up to 53 binary orders below
// the coordinates, so the coordinates alone may span 2^260.
const int kContractSpan = 260;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    Bytes in(data, size);
    const uint8_t shape = in.u8();
    const size_t n = in.below(600);
    const double scale = std::ldexp(1.0, in.centered(40));
    const double tx = in.centered(1000) * 0.125, ty = in.centered(1000) * 0.125;
    std::vector<double> xy(2 * n);
    for (size_t i = 0; i < n; ++i) {
        uint8_t kind = (shape & 0x80) ? in.u8() : shape;
        double x = 0, y = 0;
        switch (kind % 6) {
        case 0: x = in.centered(3); y = in.centered(3); break;            // tiny grid
        case 1: {                                                         // ring radius 25
            const int* q = kRing[in.below(kRingSize)];
            x = q[0];
            y = q[1];
            break;
        }
        case 2: { double t = in.centered(200); x = 2 * t; y = 3 * t + 1; break; }  // a line
        case 3:                                                           // repeat a point
            if (i > 0) {
                size_t j = in.below(static_cast<uint32_t>(i));
                x = xy[2 * j];
                y = xy[2 * j + 1];
                xy[2 * i] = x;
                xy[2 * i + 1] = y;
                continue;
            }
            break;
        case 4: x = in.centered(30000) / 64.0; y = in.centered(30000) / 64.0; break;  // grid
        default:
            if (in.u8() % 8 == 0) {  // raw bits: NaN, Inf, denormals, any magnitude
                x = in.raw_double();
                y = in.raw_double();
            } else {  // random bits within a 2^100 window, so the contract applies
                x = static_cast<double>(in.u64() >> 11);
                x = std::ldexp(x, in.centered(50) - 53);
                y = static_cast<double>(in.u64() >> 11);
                y = std::ldexp(y, in.centered(50) - 53);
                if (in.u8() & 1) x = -x;
                if (in.u8() & 1) y = -y;
            }
            break;
        }
        xy[2 * i] = x * scale + tx;
        xy[2 * i + 1] = y * scale + ty;
    }

    if (std::getenv("STRATMESH_FUZZ_VERBOSE"))
        for (size_t i = 0; i < n; ++i)
            std::fprintf(stderr, "%zu: %a %a (%.17g %.17g)\n", i, xy[2 * i], xy[2 * i + 1], xy[2 * i],
                         xy[2 * i + 1]);
    const size_t stride = 2 * sizeof(double);
    const size_t work_bytes = stratmesh::delaunay_2d_workspace_size(n);
    const size_t max_tris = stratmesh::delaunay_2d_max_triangles(n);
    std::vector<unsigned char> work(work_bytes, 0xA5);
    std::vector<uint32_t> tris(3 * max_tris);
    std::vector<uint32_t> dup(n);
    stratmesh::Delaunay2dInfo info;
    std::memset(&info, 0xCD, sizeof info);
    stratmesh::Status s = stratmesh::delaunay_2d(n ? xy.data() : nullptr, n, stride,
                                                 work.empty() ? nullptr : work.data(), work_bytes,
                                                 tris.empty() ? nullptr : tris.data(), max_tris,
                                                 &info, dup.empty() ? nullptr : dup.data());

    bool all_finite = true;
    size_t first_bad = 0;
    for (size_t i = 0; i < n && all_finite; ++i)
        if (!std::isfinite(xy[2 * i]) || !std::isfinite(xy[2 * i + 1])) {
            all_finite = false;
            first_bad = i;
        }

    // The exactness contract only covers coordinates spanning less than kContractSpan in
    // magnitude; beyond it only memory safety and the status are checked, and internal_error
    // is tolerated there (wrong predicate signs can break the algorithm's invariants).
    bool out_of_contract = false;
    {
        int lo = 0, hi = 0;
        bool any = false;
        for (double v : xy) {
            if (v == 0 || !std::isfinite(v)) continue;
            int e = 0;
            std::frexp(v, &e);
            if (!any || e < lo) lo = e;
            if (!any || e > hi) hi = e;
            any = true;
        }
        out_of_contract = hi - lo > kContractSpan;
    }
    using stratmesh::Status;
    switch (s) {
    case Status::ok:
    case Status::too_few_points:
    case Status::collinear:
    case Status::invalid_point:
        break;
    case Status::internal_error:
        if (out_of_contract) break;
        stratmesh_fuzz::fail("delaunay_2d returned internal_error");
    case Status::triangle_capacity:
        stratmesh_fuzz::fail("triangle_capacity with delaunay_2d_max_triangles() triangles");
    default:
        stratmesh_fuzz::fail("delaunay_2d returned an unexpected status", stratmesh::status_string(s));
    }
    if (!all_finite) {
        // (With fewer than 3 points the count check may come first.)
        STRATMESH_FUZZ_CHECK(s == Status::invalid_point || (n < 3 && s == Status::too_few_points),
                             "a NaN/Inf point was not refused");
        if (s == Status::invalid_point)
            STRATMESH_FUZZ_CHECK(info.first_invalid_index == first_bad, "wrong first_invalid_index");
        STRATMESH_FUZZ_CHECK(info.triangle_count == 0, "triangles reported on failure");
        return 0;
    }
    STRATMESH_FUZZ_CHECK(s != Status::invalid_point, "finite points refused as invalid");
    if (out_of_contract) return 0;

    delaunay_check::Options options;
    options.empty_circles = n <= 64;
    options.perturbed_local = n <= 64;
    delaunay_check::Report r = delaunay_check::check_triangulation(
        xy.data(), n, tris.data(), s == Status::ok ? info.triangle_count : 0,
        s == Status::ok ? dup.data() : nullptr, options);
    if (s != Status::ok) {
        STRATMESH_FUZZ_CHECK(info.triangle_count == 0, "triangles reported on failure");
        if (s == Status::too_few_points)
            STRATMESH_FUZZ_CHECK(r.distinct_points < 3, "too_few_points with 3 distinct points");
        if (s == Status::collinear)
            STRATMESH_FUZZ_CHECK(r.distinct_points >= 3 && r.collinear, "collinear, but not");
        return 0;
    }
    if (!r.ok()) stratmesh_fuzz::fail("delaunay_check failed", r.summary().c_str());
    STRATMESH_FUZZ_CHECK(!r.collinear, "ok on collinear points");
    STRATMESH_FUZZ_CHECK(info.triangle_count == r.expected_triangles, "triangle count != 2m - h - 2");
    STRATMESH_FUZZ_CHECK(info.triangle_count <= max_tris, "more triangles than the documented maximum");
    STRATMESH_FUZZ_CHECK(info.duplicate_count == n - r.distinct_points, "wrong duplicate_count");
    STRATMESH_FUZZ_CHECK(info.hull_vertex_count == r.hull_points, "wrong hull_vertex_count");

    // Determinism: a second run on a differently-filled workspace gives the same bits.
    std::vector<unsigned char> work2(work_bytes, 0x5A);
    std::vector<uint32_t> tris2(3 * max_tris);
    std::vector<uint32_t> dup2(n);
    stratmesh::Delaunay2dInfo info2;
    stratmesh::Status s2 = stratmesh::delaunay_2d(xy.data(), n, stride, work2.data(), work_bytes,
                                                  tris2.data(), max_tris, &info2, dup2.data());
    STRATMESH_FUZZ_CHECK(s2 == s, "second run: different status");
    STRATMESH_FUZZ_CHECK(std::memcmp(&info, &info2, sizeof info) == 0, "second run: different info");
    STRATMESH_FUZZ_CHECK(std::equal(tris.begin(), tris.begin() + static_cast<std::ptrdiff_t>(3 * info.triangle_count), tris2.begin()),
                         "second run: different triangles");
    STRATMESH_FUZZ_CHECK(dup == dup2, "second run: different duplicate_of");

    // Capacity one short of the result: triangle_capacity, the count needed, nothing written.
    if (info.triangle_count > 0) {
        size_t cap = info.triangle_count - 1;
        std::vector<uint32_t> small(3 * cap + 1, 0xDEADBEEFu);  // one sentinel after
        stratmesh::Delaunay2dInfo info3;
        stratmesh::Status s3 = stratmesh::delaunay_2d(xy.data(), n, stride, work2.data(), work_bytes,
                                                      small.data(), cap, &info3, nullptr);
        STRATMESH_FUZZ_CHECK(s3 == Status::triangle_capacity, "a too small triangle array was accepted");
        STRATMESH_FUZZ_CHECK(info3.triangle_count == info.triangle_count, "wrong count needed");
        for (uint32_t v : small) STRATMESH_FUZZ_CHECK(v == 0xDEADBEEFu, "triangles written on triangle_capacity");
    }
    return 0;
}
