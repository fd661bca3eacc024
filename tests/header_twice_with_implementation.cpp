// The header included twice with the implementation macro: one definition of everything.
#define STRATMESH_IMPLEMENTATION
#include "stratmesh.h"
#include "stratmesh.h"

#include <doctest/doctest.h>

TEST_CASE("the implementation compiled from a doubly-included header works") {
    const double a[2] = {0, 0}, b[2] = {1, 0}, c[2] = {0, 1};
    CHECK(stratmesh::orient2d(a, b, c) > 0);
    CHECK(stratmesh::orient2d(a, c, b) < 0);
}
