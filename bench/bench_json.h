// bench_json.h - the benchmark tools' one JSON string quoting.
#pragma once

#include <cstdio>
#include <string>

namespace bench {

// The JSON form of a string: in quotes, with quotes, backslashes and control characters
// escaped.
inline std::string json_quoted(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        const unsigned char u = static_cast<unsigned char>(c);
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (u < 0x20) {
            char escaped[8];
            std::snprintf(escaped, sizeof escaped, "\\u%04x", static_cast<unsigned>(u));
            out += escaped;
        } else {
            out += c;
        }
    }
    return out + "\"";
}

}  // namespace bench
