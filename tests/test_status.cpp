// Status names and messages come from one list; every value has a distinct, named message.
#include "stratmesh.h"

#include <doctest/doctest.h>

#include <cstring>
#include <set>
#include <string>

using stratmesh::Status;

TEST_CASE("every status has a distinct message that starts with its name") {
    const std::pair<Status, const char*> named[] = {
        {Status::ok, "ok"},
        {Status::invalid_argument, "invalid_argument"},
        {Status::too_many_points, "too_many_points"},
        {Status::invalid_point, "invalid_point"},
        {Status::too_few_points, "too_few_points"},
        {Status::collinear, "collinear"},
        {Status::out_of_memory, "out_of_memory"},
        {Status::triangle_capacity, "triangle_capacity"},
        {Status::internal_error, "internal_error"},
    };
    std::set<std::string> seen;
    for (const auto& entry : named) {
        std::string message = stratmesh::status_string(entry.first);
        CHECK(message.rfind(std::string(entry.second) + ": ", 0) == 0);
        CHECK(message.size() > std::strlen(entry.second) + 2);
        CHECK(seen.insert(message).second);
    }
}

TEST_CASE("an out-of-range status value still gets a string") {
    CHECK(std::string(stratmesh::status_string(static_cast<Status>(9999))) == "unknown status");
}

TEST_CASE("version macros agree with the version string") {
    std::string expected = std::to_string(STRATMESH_VERSION_MAJOR) + "." +
                           std::to_string(STRATMESH_VERSION_MINOR) + "." +
                           std::to_string(STRATMESH_VERSION_PATCH);
    CHECK(expected == STRATMESH_VERSION_STRING);
}
