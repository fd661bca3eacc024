// The tool's one judgement of a mesh: good, or what is poor, where, and the one action
// that helps. Printed as the summary's last line and written to the JSON report.
#ifndef STRATMESH_CLI_VERDICT_H
#define STRATMESH_CLI_VERDICT_H

#include "report_json.h"

#include <string>

namespace stratmesh_cli {

struct Verdict {
    enum Class { good, poor, not_measured } judged = not_measured;
    std::string what;    // "21% of the surface does not follow the cloud, within ...", or
                         // why the fit was not measured
    std::string action;  // for a poor mesh: the one thing to do
    std::string axis;    // the axis used: "z", "-x", or a direction "0.6,0,0.8"
};

// The verdict on a finished run (Report::diagnostics against stratmesh::kPoorMisfitFraction).
Verdict judge_mesh(const RunRecord& record);

// "good: ...", "poor: ...: <action>" or "not measured: ...", with the axis and layers used.
std::string verdict_text(const Verdict& verdict, const RunRecord& record);

const char* verdict_name(Verdict::Class judged);

} // namespace stratmesh_cli

#endif
