#include "msfem/massspring/mass_spring_model.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "model/number_text.hpp"
#include "msfem/massspring/errors.hpp"

namespace msfem::massspring {
namespace {

using detail::number_text;

void check_non_negative(double value, const std::string& item) {
  if (!(value >= 0.0) || !std::isfinite(value))
    throw ModelError(item + ": " + number_text(value) + " must be finite and >= 0");
}

}  // namespace

MassSpringModel::MassSpringModel(SpringNetwork network) : network_(std::move(network)) {
  network_.validate();
  fields_.resize(own_fields);
  const int n = network_.num_nodes();
  external_force_ = Eigen::MatrixX3d::Zero(n, 3);
  prescribed_displacement_ = Eigen::MatrixX3d::Zero(n, 3);
  constrained_.assign(n, 0);
  for (int node : network_.fixed_nodes)
    fix_node(node);
  bind_own_fields();
}

MassSpringModel::MassSpringModel(const MassSpringModel& other)
    : network_(other.network_),
      gravity_(other.gravity_),
      external_force_(other.external_force_),
      constrained_(other.constrained_),
      prescribed_displacement_(other.prescribed_displacement_),
      fields_(other.fields_) {
  bind_own_fields();
}

MassSpringModel& MassSpringModel::operator=(const MassSpringModel& other) {
  if (this == &other) return *this;
  network_ = other.network_;
  gravity_ = other.gravity_;
  external_force_ = other.external_force_;
  constrained_ = other.constrained_;
  prescribed_displacement_ = other.prescribed_displacement_;
  fields_ = other.fields_;
  bind_own_fields();
  return *this;
}

void MassSpringModel::bind_own_fields() {
  springs_ = std::make_shared<const SpringForceField>(network_);
  loads_ = std::make_shared<const NodalLoadField>(network_.masses, gravity_, external_force_);
  fields_[0] = springs_;
  fields_[1] = loads_;
}

int MassSpringModel::check_node(int node, const char* what) const {
  if (node < 0 || node >= num_nodes())
    throw ModelError(std::string(what) + " " + std::to_string(node) + ": out of range [0, " +
                     std::to_string(num_nodes()) + ")");
  return node;
}

std::vector<int> MassSpringModel::springs_in_group(const std::string& group) const {
  const int id = network_.spring_group_id(group);
  std::vector<int> members;
  for (int s = 0; s < network_.num_springs(); ++s)
    if (network_.spring_group[s] == id) members.push_back(s);
  return members;
}

void MassSpringModel::set_group_stiffness(const std::string& group, double stiffness) {
  check_non_negative(stiffness, "spring group '" + group + "' stiffness");
  for (int s : springs_in_group(group))
    network_.stiffness[s] = stiffness;
}

void MassSpringModel::scale_group_stiffness(const std::string& group, double factor) {
  check_non_negative(factor, "spring group '" + group + "' stiffness factor");
  for (int s : springs_in_group(group))
    network_.stiffness[s] *= factor;
}

void MassSpringModel::set_group_damping(const std::string& group, double damping) {
  check_non_negative(damping, "spring group '" + group + "' damping");
  for (int s : springs_in_group(group))
    network_.damping[s] = damping;
}

void MassSpringModel::set_stiffness(const Eigen::VectorXd& stiffness) {
  if (stiffness.size() != network_.num_springs())
    throw ModelError("stiffness: " + std::to_string(stiffness.size()) + " values for " +
                     std::to_string(network_.num_springs()) + " springs");
  for (Eigen::Index s = 0; s < stiffness.size(); ++s)
    check_non_negative(stiffness[s], "spring " + std::to_string(s) + " stiffness");
  network_.stiffness = stiffness;
}

void MassSpringModel::set_damping(const Eigen::VectorXd& damping) {
  if (damping.size() != network_.num_springs())
    throw ModelError("damping: " + std::to_string(damping.size()) + " values for " +
                     std::to_string(network_.num_springs()) + " springs");
  for (Eigen::Index s = 0; s < damping.size(); ++s)
    check_non_negative(damping[s], "spring " + std::to_string(s) + " damping");
  network_.damping = damping;
}

void MassSpringModel::set_node_group_mass(const std::string& group, double mass_per_node) {
  const int id = network_.node_group_id(group);
  if (!(mass_per_node > 0.0) || !std::isfinite(mass_per_node))
    throw ModelError("node group '" + group + "' mass " + number_text(mass_per_node) +
                     " must be finite and > 0");
  for (int i = 0; i < num_nodes(); ++i)
    if (network_.node_group[i] == id) network_.masses[i] = mass_per_node;
}

void MassSpringModel::set_masses(const Eigen::VectorXd& masses) {
  if (masses.size() != num_nodes())
    throw ModelError("masses: " + std::to_string(masses.size()) + " values for " +
                     std::to_string(num_nodes()) + " nodes");
  for (Eigen::Index i = 0; i < masses.size(); ++i)
    if (!(masses[i] > 0.0) || !std::isfinite(masses[i]))
      throw ModelError("node " + std::to_string(i) + ": mass " + number_text(masses[i]) +
                       " must be finite and > 0");
  network_.masses = masses;
}

void MassSpringModel::set_node_damping(double damping_per_node) {
  check_non_negative(damping_per_node, "node damping");
  network_.node_damping.setConstant(damping_per_node);
}

void MassSpringModel::set_anchor_parameters(double stiffness, double damping) {
  check_non_negative(stiffness, "anchor stiffness");
  check_non_negative(damping, "anchor damping");
  network_.anchor_stiffness.setConstant(stiffness);
  network_.anchor_damping.setConstant(damping);
}

void MassSpringModel::set_external_force(int node, const Eigen::Vector3d& force) {
  check_node(node, "external force on node");
  if (!force.allFinite())
    throw ModelError("external force on node " + std::to_string(node) + ": not finite");
  external_force_.row(node) = force.transpose();
}

void MassSpringModel::clear_external_forces() {
  external_force_.setZero();
}

void MassSpringModel::prescribe_displacement(int node, const Eigen::Vector3d& displacement) {
  check_node(node, "prescribed node");
  if (!displacement.allFinite())
    throw ModelError("prescribed node " + std::to_string(node) + ": displacement not finite");
  constrained_[node] = 1;
  prescribed_displacement_.row(node) = displacement.transpose();
}

void MassSpringModel::release_node(int node) {
  check_node(node, "released node");
  constrained_[node] = 0;
  prescribed_displacement_.row(node).setZero();
}

Eigen::Vector3d MassSpringModel::constrained_target(int node) const {
  check_node(node, "node");
  return (network_.rest_positions.row(node) + prescribed_displacement_.row(node)).transpose();
}

namespace {

void check_field(const ForceField* field, int num_nodes) {
  if (!field) throw ModelError("force field: none given");
  if (field->num_dofs() != 3 * num_nodes)
    throw ModelError(field->name() + ": built for " + std::to_string(field->num_dofs() / 3) +
                     " nodes, model has " + std::to_string(num_nodes));
}

}  // namespace

void MassSpringModel::add_field(std::shared_ptr<const ForceField> field) {
  check_field(field.get(), num_nodes());
  fields_.push_back(std::move(field));
}

void MassSpringModel::replace_field(std::size_t index, std::shared_ptr<const ForceField> field) {
  if (index >= fields_.size())
    throw ModelError("force field " + std::to_string(index) + ": the model has " +
                     std::to_string(fields_.size()));
  if (index < own_fields)
    throw ModelError("force field " + std::to_string(index) + " is the model's " +
                     fields_[index]->name() +
                     ": change it through the model's stiffness, damping, mass and load "
                     "parameters");
  check_field(field.get(), num_nodes());
  fields_[index] = std::move(field);
}

void MassSpringModel::set_contact(const SphereContactForceField& contact) {
  set_field<ToolContact>(std::make_shared<const SphereContactForceField>(contact));
}

void MassSpringModel::set_contact(const SurfaceContactForceField& contact) {
  set_field<ToolContact>(std::make_shared<const SurfaceContactForceField>(contact));
}

void MassSpringModel::set_volume(const VolumeForceField& volume) {
  set_field<VolumeForceField>(std::make_shared<const VolumeForceField>(volume));
}

Eigen::MatrixX3d MassSpringModel::surface_displacement(const Eigen::VectorXd& x) const {
  Eigen::MatrixX3d u(network_.surface_nodes.size(), 3);
  for (std::size_t k = 0; k < network_.surface_nodes.size(); ++k) {
    const int i = network_.surface_nodes[k];
    u.row(k) = x.segment<3>(3 * i).transpose() - network_.rest_positions.row(i);
  }
  return u;
}

}  // namespace msfem::massspring
