// The short human summary the tool prints on stderr.
#ifndef STRATMESH_CLI_SUMMARY_H
#define STRATMESH_CLI_SUMMARY_H

#include "report_json.h"

#include <cstdio>

namespace stratmesh_cli {

void print_summary(std::FILE* out, const RunRecord& record);

} // namespace stratmesh_cli

#endif
