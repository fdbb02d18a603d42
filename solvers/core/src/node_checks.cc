#include "node_checks.h"

#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers::internal {

void CheckNodes(const std::vector<int>& nodes, const std::string& what) {
  if (nodes.empty()) throw InvalidInputError(what + ": the node list is empty");
  for (int node : nodes)
    if (node < 0) {
      std::ostringstream msg;
      msg << what << ": node " << node << " is invalid: must be >= 0";
      throw InvalidInputError(msg.str());
    }
}

void CheckNodesFit(const std::vector<int>& nodes, int num_nodes, const std::string& what) {
  for (int node : nodes)
    if (node >= num_nodes) {
      std::ostringstream msg;
      msg << what << ": node " << node << " is out of range: the mesh has " << num_nodes << " nodes";
      throw InvalidInputError(msg.str());
    }
}

}  // namespace diffpd::solvers::internal
