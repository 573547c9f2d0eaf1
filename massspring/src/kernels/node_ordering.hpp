#pragma once

// Node renumbering for memory locality (internal).

#include <Eigen/Core>
#include <vector>

namespace msfem::massspring::detail {

/// Reverse Cuthill-McKee order of the graph with `num_nodes` nodes and the given edges: a
/// breadth-first order from a low-degree node, neighbours by increasing degree, reversed. Returns
/// order[new_id] = old_id; disconnected parts follow one another.
std::vector<int> reverse_cuthill_mckee(int num_nodes, const Eigen::MatrixX2i& edges);

}  // namespace msfem::massspring::detail
