// Checks of node lists shared by the parameter blocks (internal).
#pragma once

#include <string>
#include <vector>

namespace diffpd::solvers::internal {

// Throws InvalidInputError "<what>: the node list is empty" or
// "<what>: node -1 is invalid: must be >= 0".
void CheckNodes(const std::vector<int>& nodes, const std::string& what);
// Throws InvalidInputError "<what>: node 1000 is out of range: the mesh has 45 nodes".
void CheckNodesFit(const std::vector<int>& nodes, int num_nodes, const std::string& what);

}  // namespace diffpd::solvers::internal
