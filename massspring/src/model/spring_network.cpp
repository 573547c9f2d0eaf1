#include "msfem/massspring/spring_network.hpp"

#include <cmath>
#include <sstream>

#include "model/number_text.hpp"
#include "msfem/massspring/errors.hpp"

namespace msfem::massspring {
namespace {

[[noreturn]] void fail(const std::string& item, const std::string& what) {
  throw ModelError(item + ": " + what);
}

using detail::number_text;

void check_size(Eigen::Index actual, Eigen::Index expected, const std::string& name) {
  if (actual != expected)
    fail(name, "has " + std::to_string(actual) + " entries, expected " + std::to_string(expected));
}

void check_node(int node, int num_nodes, const std::string& item) {
  if (node < 0 || node >= num_nodes)
    fail(item, "node id " + std::to_string(node) + " out of range [0, " +
                   std::to_string(num_nodes) + ")");
}

}  // namespace

int SpringNetwork::spring_group_id(const std::string& name) const {
  for (std::size_t g = 0; g < spring_group_names.size(); ++g)
    if (spring_group_names[g] == name) return static_cast<int>(g);
  throw ModelError("spring group '" + name + "': no such group");
}

int SpringNetwork::node_group_id(const std::string& name) const {
  for (std::size_t g = 0; g < node_group_names.size(); ++g)
    if (node_group_names[g] == name) return static_cast<int>(g);
  throw ModelError("node group '" + name + "': no such group");
}

std::vector<int> SpringNetwork::spring_group_sizes() const {
  std::vector<int> sizes(spring_group_names.size(), 0);
  for (Eigen::Index s = 0; s < spring_group.size(); ++s)
    ++sizes[spring_group[s]];
  return sizes;
}

void SpringNetwork::validate() const {
  const int n = num_nodes();
  const int s = num_springs();
  const int a = num_anchors();
  check_size(masses.size(), n, "masses");
  check_size(node_damping.size(), n, "node_damping");
  check_size(node_group.size(), n, "node_group");
  check_size(stiffness.size(), s, "stiffness");
  check_size(damping.size(), s, "damping");
  check_size(rest_length.size(), s, "rest_length");
  check_size(spring_group.size(), s, "spring_group");
  check_size(anchor_point.rows(), a, "anchor_point");
  check_size(anchor_stiffness.size(), a, "anchor_stiffness");
  check_size(anchor_damping.size(), a, "anchor_damping");

  for (int i = 0; i < n; ++i) {
    const std::string item = "node " + std::to_string(i);
    if (!rest_positions.row(i).allFinite()) fail(item, "rest position is not finite");
    if (!(masses[i] > 0.0) || !std::isfinite(masses[i]))
      fail(item, "mass " + number_text(masses[i]) + " must be finite and > 0");
    if (!(node_damping[i] >= 0.0) || !std::isfinite(node_damping[i]))
      fail(item, "damping " + number_text(node_damping[i]) + " must be finite and >= 0");
    if (node_group[i] < 0 || node_group[i] >= static_cast<int>(node_group_names.size()))
      fail(item, "node group " + std::to_string(node_group[i]) + " out of range");
  }
  for (int k = 0; k < s; ++k) {
    const std::string item = "spring " + std::to_string(k);
    check_node(springs(k, 0), n, item);
    check_node(springs(k, 1), n, item);
    if (springs(k, 0) == springs(k, 1))
      fail(item, "connects node " + std::to_string(springs(k, 0)) + " to itself");
    if (!(stiffness[k] >= 0.0) || !std::isfinite(stiffness[k]))
      fail(item, "stiffness " + number_text(stiffness[k]) + " must be finite and >= 0");
    if (!(damping[k] >= 0.0) || !std::isfinite(damping[k]))
      fail(item, "damping " + number_text(damping[k]) + " must be finite and >= 0");
    if (!(rest_length[k] > 0.0) || !std::isfinite(rest_length[k]))
      fail(item, "rest length " + number_text(rest_length[k]) +
                     " must be finite and > 0 (zero-length spring)");
    const double current =
        (rest_positions.row(springs(k, 1)) - rest_positions.row(springs(k, 0))).norm();
    if (!(current > 0.0))
      fail(item, "zero-length spring: nodes " + std::to_string(springs(k, 0)) + " and " +
                     std::to_string(springs(k, 1)) + " coincide");
    if (spring_group[k] < 0 || spring_group[k] >= static_cast<int>(spring_group_names.size()))
      fail(item, "spring group " + std::to_string(spring_group[k]) + " out of range");
  }
  for (int k = 0; k < a; ++k) {
    const std::string item = "anchor " + std::to_string(k);
    check_node(anchor_node[k], n, item);
    if (!anchor_point.row(k).allFinite()) fail(item, "anchor point is not finite");
    if (!(anchor_stiffness[k] >= 0.0) || !std::isfinite(anchor_stiffness[k]))
      fail(item, "stiffness " + number_text(anchor_stiffness[k]) + " must be finite and >= 0");
    if (!(anchor_damping[k] >= 0.0) || !std::isfinite(anchor_damping[k]))
      fail(item, "damping " + number_text(anchor_damping[k]) + " must be finite and >= 0");
  }
  for (int node : surface_nodes)
    check_node(node, n, "surface node list");
  for (int node : fixed_nodes)
    check_node(node, n, "fixed node list");
}

int add_springs(SpringNetwork& network, const std::vector<std::array<int, 2>>& pairs,
                const std::string& group_name) {
  int group = -1;
  for (std::size_t g = 0; g < network.spring_group_names.size(); ++g)
    if (network.spring_group_names[g] == group_name) group = static_cast<int>(g);
  if (group < 0) {
    group = static_cast<int>(network.spring_group_names.size());
    network.spring_group_names.push_back(group_name);
  }
  const Eigen::Index old = network.springs.rows();
  const Eigen::Index total = old + static_cast<Eigen::Index>(pairs.size());
  network.springs.conservativeResize(total, 2);
  network.stiffness.conservativeResize(total);
  network.damping.conservativeResize(total);
  network.rest_length.conservativeResize(total);
  network.spring_group.conservativeResize(total);
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    const Eigen::Index k = old + static_cast<Eigen::Index>(p);
    const int i = pairs[p][0];
    const int j = pairs[p][1];
    const int n = network.num_nodes();
    check_node(i, n, "spring " + std::to_string(k));
    check_node(j, n, "spring " + std::to_string(k));
    network.springs(k, 0) = i;
    network.springs(k, 1) = j;
    network.stiffness[k] = 0.0;
    network.damping[k] = 0.0;
    network.rest_length[k] = (network.rest_positions.row(j) - network.rest_positions.row(i)).norm();
    if (!(network.rest_length[k] > 0.0))
      fail("spring " + std::to_string(k) + " (" + group_name + ")",
           "zero-length spring: nodes " + std::to_string(i) + " and " + std::to_string(j) +
               " coincide");
    network.spring_group[k] = group;
  }
  return group;
}

Eigen::VectorXd flatten(const Eigen::MatrixX3d& points) {
  Eigen::VectorXd state(3 * points.rows());
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    state.segment<3>(3 * i) = points.row(i).transpose();
  return state;
}

Eigen::MatrixX3d unflatten(const Eigen::VectorXd& state) {
  Eigen::MatrixX3d points(state.size() / 3, 3);
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    points.row(i) = state.segment<3>(3 * i).transpose();
  return points;
}

}  // namespace msfem::massspring
