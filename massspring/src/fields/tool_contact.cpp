#include "msfem/massspring/tool_contact.hpp"

#include <algorithm>
#include <cmath>

#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/mass_spring_model.hpp"

namespace msfem::massspring {
namespace {

Eigen::Vector3d unit_direction(const ToolIndentation& indent) {
  const double norm = indent.inward_direction.norm();
  if (!(norm > 0.0) || !std::isfinite(norm))
    throw ModelError("tool indentation: inward direction must be a finite non-zero vector");
  if (!(indent.radius > 0.0) || !std::isfinite(indent.radius))
    throw ModelError("tool indentation: radius " + std::to_string(indent.radius) +
                     " must be finite and > 0");
  if (!(indent.depth >= 0.0) || !std::isfinite(indent.depth))
    throw ModelError("tool indentation: depth " + std::to_string(indent.depth) +
                     " must be finite and >= 0");
  return indent.inward_direction / norm;
}

}  // namespace

SphereTool ToolIndentation::tool() const {
  const Eigen::Vector3d u = unit_direction(*this);
  return {contact_point + u * (depth - radius), radius};
}

SphereContactForceField::SphereContactForceField(int num_nodes, std::vector<int> nodes,
                                                 SphereTool tool, double penalty_stiffness)
    : num_nodes_(num_nodes), nodes_(std::move(nodes)), tool_(tool), penalty_(penalty_stiffness) {
  if (!(tool_.radius > 0.0) || !std::isfinite(tool_.radius))
    throw ModelError("sphere contact: radius must be finite and > 0");
  if (!(penalty_ > 0.0) || !std::isfinite(penalty_))
    throw ModelError("sphere contact: penalty stiffness must be finite and > 0");
  for (int node : nodes_)
    if (node < 0 || node >= num_nodes_)
      throw ModelError("sphere contact: node " + std::to_string(node) + " out of range");
}

void SphereContactForceField::add_force(const Eigen::VectorXd& x, const Eigen::VectorXd&,
                                        Eigen::VectorXd& f) const {
  for (int i : nodes_) {
    const Eigen::Vector3d w = x.segment<3>(3 * i) - tool_.center;
    const double rho = w.norm();
    if (rho >= tool_.radius || !(rho > 0.0)) continue;
    f.segment<3>(3 * i) += penalty_ * (tool_.radius - rho) / rho * w;
  }
}

double SphereContactForceField::potential_energy(const Eigen::VectorXd& x) const {
  double energy = 0.0;
  for (int i : nodes_) {
    const double gap = tool_.radius - (x.segment<3>(3 * i) - tool_.center).norm();
    if (gap > 0.0) energy += 0.5 * penalty_ * gap * gap;
  }
  return energy;
}

// The node's penalty term with its definite stiffness (the static relaxation's local Newton).
double SphereContactForceField::add_node_term(int, const Eigen::Vector3d& p, Eigen::Vector3d& f,
                                              Eigen::Matrix3d& k) const {
  const Eigen::Vector3d w = p - tool_.center;
  const double rho = w.norm();
  const double gap = tool_.radius - rho;
  if (!(gap > 0.0 && rho > 0.0)) return 0.0;
  f += penalty_ * gap / rho * w;
  k += penalty_ * (w / rho) * (w / rho).transpose();
  return 0.5 * penalty_ * gap * gap;
}

Eigen::Matrix3d SphereContactForceField::block(const Eigen::Vector3d& position,
                                               Linearisation mode) const {
  const Eigen::Vector3d w = position - tool_.center;
  const double rho = w.norm();
  if (rho >= tool_.radius || !(rho > 0.0)) return Eigen::Matrix3d::Zero();
  const Eigen::Vector3d n = w / rho;
  const Eigen::Matrix3d nn = n * n.transpose();
  // ∂[k_p (r - ρ) n]/∂x = k_p [ -n nᵀ + (r - ρ)/ρ (I - n nᵀ) ]; the second term is positive, so the
  // definite linearisation drops it.
  Eigen::Matrix3d result = -penalty_ * nn;
  if (mode == Linearisation::exact)
    result += penalty_ * (tool_.radius - rho) / rho * (Eigen::Matrix3d::Identity() - nn);
  return result;
}

void SphereContactForceField::add_dfdx_product(const Eigen::VectorXd& x, const Eigen::VectorXd&,
                                               const Eigen::VectorXd& dx, Eigen::VectorXd& df,
                                               Linearisation mode) const {
  for (int i : nodes_)
    df.segment<3>(3 * i) += block(x.segment<3>(3 * i), mode) * dx.segment<3>(3 * i);
}

void SphereContactForceField::add_dfdx_triplets(const Eigen::VectorXd& x, const Eigen::VectorXd&,
                                                Triplets& triplets, Linearisation mode) const {
  for (int i : nodes_) {
    const Eigen::Matrix3d b = block(x.segment<3>(3 * i), mode);
    if (b.isZero(0.0)) continue;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        triplets.emplace_back(3 * i + r, 3 * i + c, b(r, c));
  }
}

std::vector<int> prescribe_contact_patch(MassSpringModel& model, const ToolIndentation& indent) {
  const Eigen::Vector3d u = unit_direction(indent);
  const SphereTool tool = indent.tool();
  std::vector<int> patch;
  for (int i : model.network().surface_nodes) {
    const Eigen::Vector3d w = model.network().rest_positions.row(i).transpose() - tool.center;
    const double squared_gap = tool.radius * tool.radius - w.squaredNorm();
    if (squared_gap <= 0.0) continue;
    // Larger root of |w + t u| = r: where the node leaves the sphere moving along u.
    const double b = u.dot(w);
    const double t = -b + std::sqrt(b * b + squared_gap);
    model.prescribe_displacement(i, t * u);
    patch.push_back(i);
  }
  if (patch.empty())
    throw ModelError("tool indentation: no surface node inside the tool (depth " +
                     std::to_string(indent.depth) + " m, radius " + std::to_string(indent.radius) +
                     " m)");
  return patch;
}

double stiffest_surface_node(const MassSpringModel& model) {
  const SpringNetwork& net = model.network();
  Eigen::VectorXd summed = Eigen::VectorXd::Zero(net.num_nodes());
  for (int s = 0; s < net.num_springs(); ++s) {
    summed[net.springs(s, 0)] += net.stiffness[s];
    summed[net.springs(s, 1)] += net.stiffness[s];
  }
  for (int a = 0; a < net.num_anchors(); ++a)
    summed[net.anchor_node[a]] += net.anchor_stiffness[a];
  double largest = 0.0;
  for (int i : net.surface_nodes)
    largest = std::max(largest, summed[i]);
  return largest > 0.0 ? largest : 1.0;
}

double activate_sphere_contact(MassSpringModel& model, const ToolIndentation& indent,
                               double penalty_stiffness) {
  const SpringNetwork& net = model.network();
  if (penalty_stiffness <= 0.0) penalty_stiffness = 1000.0 * stiffest_surface_node(model);
  model.set_contact(SphereContactForceField(net.num_nodes(), net.surface_nodes, indent.tool(),
                                            penalty_stiffness));
  return penalty_stiffness;
}

Eigen::Vector3d patch_reaction_force(const MechanicalSystem& model, const Eigen::VectorXd& x,
                                     const std::vector<int>& patch) {
  const Eigen::VectorXd f = model.force(x, Eigen::VectorXd::Zero(x.size()));
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (int i : patch)
    total += f.segment<3>(3 * i);
  return total;
}

Eigen::Vector3d contact_reaction_force(const MechanicalSystem& model, const Eigen::VectorXd& x) {
  const auto* contact = model.find_field<ToolContact>();
  if (!contact) return Eigen::Vector3d::Zero();
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  contact->add_force(x, Eigen::VectorXd::Zero(x.size()), f);
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (int i : contact->nodes())
    total -= f.segment<3>(3 * i);
  return total;
}

int project_out_of_tool(const MechanicalSystem& model, Eigen::VectorXd& x, Eigen::VectorXd& v) {
  const auto* contact = model.find_field<ToolContact>();
  if (!contact) return 0;
  const SphereTool& tool = contact->tool();
  int projected = 0;
  for (int i : contact->nodes()) {
    const Eigen::Vector3d w = x.segment<3>(3 * i) - tool.center;
    const double rho = w.norm();
    if (rho >= tool.radius || !(rho > 0.0)) continue;
    const Eigen::Vector3d n = w / rho;
    x.segment<3>(3 * i) = tool.center + tool.radius * n;
    const double inward = v.segment<3>(3 * i).dot(n);
    if (inward < 0.0) v.segment<3>(3 * i) -= inward * n;
    ++projected;
  }
  return projected;
}

}  // namespace msfem::massspring
