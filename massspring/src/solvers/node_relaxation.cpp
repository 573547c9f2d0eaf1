#include "node_relaxation.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <utility>

#include "msfem/massspring/nodal_load_field.hpp"
#include "msfem/massspring/spring_force_field.hpp"

namespace msfem::massspring::detail {
namespace {

// CSR lists of items per node from an item -> node(s) map.
template <typename NodesOf>
void bucket(int num_nodes, int num_items, int per_item, NodesOf nodes_of, std::vector<int>& start,
            std::vector<int>& items) {
  start.assign(num_nodes + 1, 0);
  for (int s = 0; s < num_items; ++s)
    for (int e = 0; e < per_item; ++e)
      ++start[nodes_of(s, e) + 1];
  for (int i = 0; i < num_nodes; ++i)
    start[i + 1] += start[i];
  items.resize(start.back());
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (int s = 0; s < num_items; ++s)
    for (int e = 0; e < per_item; ++e)
      items[fill[nodes_of(s, e)]++] = s;
}

}  // namespace

NodeRelaxation::NodeRelaxation(const MechanicalSystem& model) : model_(model) {
  // Without springs (a system of other fields alone) only the nodewise fields are relaxed here.
  static const SpringNetwork no_springs;
  springs_field_ = model.find_field<SpringForceField>();
  loads_ = model.find_field<NodalLoadField>();
  network_ = springs_field_ ? &springs_field_->network() : &no_springs;
  const SpringNetwork& net = *network_;
  const int nodes = model.num_nodes();
  bucket(
      nodes, net.num_springs(), 2, [&](int s, int e) { return net.springs(s, e); }, spring_start_,
      springs_);
  bucket(
      nodes, net.num_anchors(), 1, [&](int a, int) { return net.anchor_node[a]; }, anchor_start_,
      anchors_);
  // A nodewise field's energy (a node contact's) is local to each node, and relaxed here with the
  // springs'. Any other field's may couple its nodes (a volume element's couples all of it, a
  // surface contact's triangle its three): those nodes are left to Newton.
  left_to_newton_.assign(static_cast<std::size_t>(nodes), 0);
  std::vector<std::pair<int, const ForceField*>> terms;
  for (const auto& field : model.fields()) {
    if (field.get() == springs_field_ || field.get() == loads_) continue;
    for (int i : field->nodes())
      if (field->nodewise())
        terms.emplace_back(i, field.get());
      else
        left_to_newton_[static_cast<std::size_t>(i)] = 1;
  }
  bucket(
      nodes, static_cast<int>(terms.size()), 1, [&](int t, int) { return terms[t].first; },
      node_term_start_, node_term_);
  node_term_field_.resize(terms.size());
  for (std::size_t t = 0; t < terms.size(); ++t)
    node_term_field_[t] = terms[t].second;
}

double NodeRelaxation::local(const Eigen::VectorXd& x, int i, const Eigen::Vector3d& p,
                             Eigen::Vector3d* force, Eigen::Matrix3d* stiffness) const {
  const SpringNetwork& net = *network_;
  const Eigen::Vector3d load = loads_ ? loads_->load(i) : Eigen::Vector3d::Zero();
  const Eigen::Matrix3d identity = Eigen::Matrix3d::Identity();
  double energy = -load.dot(p);
  Eigen::Vector3d f = load;
  Eigen::Matrix3d k = Eigen::Matrix3d::Zero();
  for (int q = spring_start_[i]; q < spring_start_[i + 1]; ++q) {
    const int s = springs_[q];
    const int j = net.springs(s, 0) == i ? net.springs(s, 1) : net.springs(s, 0);
    const Eigen::Vector3d d = x.segment<3>(3 * j) - p;
    const double length = d.norm();
    const double stretch = length - net.rest_length[s];
    energy += 0.5 * net.stiffness[s] * stretch * stretch;
    if (!(length > 0.0)) continue;
    const Eigen::Vector3d n = d / length;
    f += net.stiffness[s] * stretch * n;
    // Compressed springs' negative transverse term dropped: the 3x3 stays definite.
    const Eigen::Matrix3d nn = n * n.transpose();
    k += net.stiffness[s] * (nn + std::max(stretch / length, 0.0) * (identity - nn));
  }
  for (int q = anchor_start_[i]; q < anchor_start_[i + 1]; ++q) {
    const int a = anchors_[q];
    const Eigen::Vector3d d = p - net.anchor_point.row(a).transpose();
    energy += 0.5 * net.anchor_stiffness[a] * d.squaredNorm();
    f -= net.anchor_stiffness[a] * d;
    k += net.anchor_stiffness[a] * identity;
  }
  for (int q = node_term_start_[i]; q < node_term_start_[i + 1]; ++q)
    energy += node_term_field_[node_term_[q]]->add_node_term(i, p, f, k);
  if (force) *force = f;
  if (stiffness) *stiffness = k;
  return energy;
}

void NodeRelaxation::relax_node(Eigen::VectorXd& x, int i) const {
  for (int newton = 0; newton < 5; ++newton) {
    const Eigen::Vector3d p = x.segment<3>(3 * i);
    Eigen::Vector3d f;
    Eigen::Matrix3d k;
    const double energy = local(x, i, p, &f, &k);
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(k);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 0.0).all()) return;
    const Eigen::Vector3d step = ldlt.solve(f);
    if (!step.allFinite() || !(step.dot(f) > 0.0)) return;
    double alpha = 1.0;
    for (; alpha > 1e-6; alpha *= 0.5)
      if (local(x, i, p + alpha * step, nullptr, nullptr) < energy) break;
    if (!(alpha > 1e-6)) return;
    x.segment<3>(3 * i) = p + alpha * step;
    if (alpha * step.norm() <= 1e-14 * p.norm()) return;
  }
}

int NodeRelaxation::relax(Eigen::VectorXd& x, const Eigen::VectorXd& f, double fraction,
                          int sweeps) const {
  double largest = 0.0;
  for (int i = 0; i < model_.num_nodes(); ++i)
    largest = std::max(largest, f.segment<3>(3 * i).norm());
  std::vector<int> nodes;
  for (int i = 0; i < model_.num_nodes(); ++i)
    if (!model_.is_constrained(i) && !left_to_newton_[i] && largest > 0.0 &&
        f.segment<3>(3 * i).norm() >= fraction * largest)
      nodes.push_back(i);
  for (int sweep = 0; sweep < sweeps; ++sweep)
    for (int i : nodes)
      relax_node(x, i);
  return static_cast<int>(nodes.size());
}

}  // namespace msfem::massspring::detail
