#include "node_ordering.hpp"

#include <algorithm>
#include <numeric>

namespace msfem::massspring::detail {

std::vector<int> reverse_cuthill_mckee(int num_nodes, const Eigen::MatrixX2i& edges) {
  std::vector<int> degree(num_nodes, 0);
  for (Eigen::Index e = 0; e < edges.rows(); ++e) {
    ++degree[edges(e, 0)];
    ++degree[edges(e, 1)];
  }
  std::vector<int> offset(num_nodes + 1, 0);
  for (int i = 0; i < num_nodes; ++i)
    offset[i + 1] = offset[i] + degree[i];
  std::vector<int> neighbours(offset.back());
  std::vector<int> fill(offset.begin(), offset.end() - 1);
  for (Eigen::Index e = 0; e < edges.rows(); ++e) {
    neighbours[fill[edges(e, 0)]++] = edges(e, 1);
    neighbours[fill[edges(e, 1)]++] = edges(e, 0);
  }
  std::vector<int> by_degree(num_nodes);
  std::iota(by_degree.begin(), by_degree.end(), 0);
  std::stable_sort(by_degree.begin(), by_degree.end(),
                   [&](int a, int b) { return degree[a] < degree[b]; });

  std::vector<int> order;
  order.reserve(num_nodes);
  std::vector<char> visited(num_nodes, 0);
  std::vector<int> scratch;
  for (int start : by_degree) {
    if (visited[start]) continue;
    visited[start] = 1;
    std::size_t head = order.size();
    order.push_back(start);
    while (head < order.size()) {
      const int node = order[head++];
      scratch.clear();
      for (int k = offset[node]; k < offset[node + 1]; ++k)
        if (!visited[neighbours[k]]) {
          visited[neighbours[k]] = 1;
          scratch.push_back(neighbours[k]);
        }
      std::sort(scratch.begin(), scratch.end(),
                [&](int a, int b) { return degree[a] < degree[b]; });
      order.insert(order.end(), scratch.begin(), scratch.end());
    }
  }
  std::reverse(order.begin(), order.end());
  return order;
}

}  // namespace msfem::massspring::detail
