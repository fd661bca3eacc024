// The tests' mesh checker on a reconstructed mesh of an analytic shape: its surface is the
// shape's, its axis the report's.
#pragma once

#include "mesh_check.h"
#include "reconstructed.h"
#include "shapes.h"

#include <doctest/doctest.h>

namespace shape_check {

inline mesh_check::Result check(const shapes::Shape& s, const reconstructed::Mesh& m) {
    mesh_check::Input in;
    in.points = s.xyz.data();
    in.point_count = s.size();
    in.triangles = m.triangles.data();
    in.triangle_count = m.triangles.size() / 3;
    for (int k = 0; k < 3; ++k) in.axis_direction[k] = m.report.axis[k];
    in.surface = [&s](const double* p) { return s.deviation(p); };
    return mesh_check::check(in);
}

// One oriented manifold through every point, with no crossing triangles, within
// `deviation` of the surface.
inline void check_whole(const mesh_check::Result& r, double deviation) {
    INFO(r.summary());
    CHECK(r.manifold());
    CHECK(r.oriented());
    CHECK(r.components == 1);
    CHECK(r.unused_expected == 0);
    CHECK(r.intersecting_pairs == 0);
    CHECK(r.vertex_overlaps == 0);
    CHECK(r.max_deviation() < deviation);
}

}  // namespace shape_check
