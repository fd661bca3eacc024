// What the tool tells a user on stderr: a short summary, its details with --verbose, and
// the warnings, which are printed even with --quiet.
#ifndef STRATMESH_CLI_SUMMARY_H
#define STRATMESH_CLI_SUMMARY_H

#include "report_json.h"
#include "verdict.h"

#include <cstdio>
#include <string>
#include <vector>

namespace stratmesh_cli {

// What a user should know of the output besides the verdict, each a sentence without the
// "stratmesh: warning: " prefix: branches left apart, points left out, caps left open,
// input faces ignored, cuts outside the cloud.
std::vector<std::string> run_warnings(const RunRecord& record);

// The input faces left out of the cloud, or an empty string.
std::string faces_warning(const RunRecord& record);

// A sentence of the library's (Report::detail) in the tool's words: the library's option
// names become the command line's (drop_outliers: --drop-outliers).
std::string in_tool_words(const char* library_sentence);

// Each warning on a line of its own, "stratmesh: warning: ...".
void print_warnings(std::FILE* out, const std::vector<std::string>& warnings);

// At most six lines (input and output, points, layers, triangles and ends, warnings, the
// verdict last); `verbose` adds the folds, the branches, the parts, the threads, the times,
// the memory and the stream. The warnings themselves are print_warnings'.
void print_summary(std::FILE* out, const RunRecord& record, const Verdict& verdict,
                   size_t warning_count, bool verbose);

} // namespace stratmesh_cli

#endif
