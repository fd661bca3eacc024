// The library's view of a generated shape: its cloud and its stacking axis as the options
// say it. Shared by the reconstruction and stream suites.
#pragma once

#include "stratmesh.h"
#include "support/shapes.h"

namespace library_options {

inline stratmesh::Cloud cloud_of(const shapes::Shape& s) {
    return stratmesh::Cloud{s.xyz.data(), s.size(), 0, stratmesh::Scalar::float64};
}

inline stratmesh::Options axis_options(const shapes::Shape& s) {
    stratmesh::Options o = {};
    switch (s.pose) {
    case shapes::Pose::z: o.axis = stratmesh::Axis::z; break;
    case shapes::Pose::x: o.axis = stratmesh::Axis::x; break;
    case shapes::Pose::tilted:
        o.axis = stratmesh::Axis::direction;
        s.axis_direction(o.direction);
        break;
    }
    return o;
}

}  // namespace library_options
