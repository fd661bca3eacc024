// Status names and messages come from one list; every value has a distinct, named message.
#include "stratmesh.h"

#include <doctest/doctest.h>

#include <cstring>
#include <set>
#include <string>

using stratmesh::Status;

TEST_CASE("every status has a distinct message that starts with its name") {
    // Every status, from the list that generates the enum: a new one is tested here too.
#define STRATMESH_TEST_STATUS_ENTRY(name, message) {Status::name, #name},
    const std::pair<Status, const char*> named[] = {
        STRATMESH_STATUS_LIST(STRATMESH_TEST_STATUS_ENTRY)};
#undef STRATMESH_TEST_STATUS_ENTRY
    // The list starts at ok and counts up without gaps, as the enum's values do.
    for (size_t k = 0; k < sizeof named / sizeof named[0]; ++k)
        CHECK(static_cast<size_t>(named[k].first) == k);
    CHECK(sizeof named / sizeof named[0] >= 14);
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
