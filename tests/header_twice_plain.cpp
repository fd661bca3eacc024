// A second translation unit that includes the header plainly, twice, and calls into the
// implementation compiled in the other one.
#include "stratmesh.h"
#include "stratmesh.h"

#include <doctest/doctest.h>

#include <cstring>

TEST_CASE("a plain include links against the implementation of another file") {
    CHECK(std::strncmp(stratmesh::status_string(stratmesh::Status::ok), "ok", 2) == 0);
    const double a[2] = {0, 0}, b[2] = {2, 0}, c[2] = {0, 2}, inside[2] = {0.5, 0.5};
    CHECK(stratmesh::incircle(a, b, c, inside) > 0);
}
