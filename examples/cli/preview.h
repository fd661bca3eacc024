// --preview FILE.svg: a shaded picture of the mesh, for a look without a viewer.
#ifndef STRATMESH_CLI_PREVIEW_H
#define STRATMESH_CLI_PREVIEW_H

#include "mesh_io.h"
#include "stratmesh.h"

#include <string>
#include <vector>

namespace stratmesh_cli {

// The mesh seen from two sides across `axis` (a unit vector, drawn upwards), front and
// side, side by side: orthographic, each triangle a polygon (one per triangle and view),
// painted far to near, shaded by its angle to the light (both faces lit, so that the inside
// shows through an open end) and tinted by its layer, alternately blue and orange
// (`layers` bottom up; one tint if empty); the boundary edges drawn over them in red.
// Written into `file` (opened, safe_output.h), which it completes; false with a message
// naming the file on failure.
bool write_preview_svg(AtomicFile& file, const MeshView& mesh, const double axis[3],
                       const std::vector<stratmesh::LayerInfo>& layers, std::string& error);

} // namespace stratmesh_cli

#endif
