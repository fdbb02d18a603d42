// TetGen .node/.ele parsing without validation (internal; shared by
// ReadTetGen and TetrahedralizeSurface).
#pragma once

#include <string>

#include "diffpd/mesh.h"

namespace diffpd::internal {

// The tet4 mesh of the files, tets as written; see ReadTetGen for the format
// and the messages. Does not call ValidateMesh.
Mesh ReadTetGenFiles(const std::string& node_path, const std::string& ele_path);

}  // namespace diffpd::internal
