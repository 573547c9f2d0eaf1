#pragma once

// A force field written outside massspring, as a simulator would write its own: a grasper that
// pulls the centroid of a set of nodes toward a point it moves between steps, through a spring k
// and a dashpot c on the centroid,
//   U = ½ k |x̄ - p|²,   f_i = -(k/n) (x̄ - p) - (c/n) v̄   for the n grasped nodes,
// so that ∂f_i/∂x_j = -(k/n²) I and ∂f_i/∂v_j = -(c/n²) I couple every pair of grasped nodes. Its
// one coefficient group, "grasp", scales k. It overrides nothing but what ForceField requires:
// the parts, diagonal blocks and tangent come from the base class.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "msfem/massspring/force_model.hpp"

namespace msfem::massspring::testing {

class Grasper : public ForceField {
 public:
  Grasper(int num_nodes, std::vector<int> nodes, Eigen::Vector3d point, double k, double c)
      : num_nodes_(num_nodes), nodes_(std::move(nodes)), point_(point), k_(k), c_(c) {}

  /// Moves the point the grasper pulls toward (between steps, as a simulator moves its tool).
  void move_to(const Eigen::Vector3d& point) { point_ = point; }
  double stiffness() const { return k_; }

  int num_dofs() const override { return 3 * num_nodes_; }
  const std::vector<int>& nodes() const override { return nodes_; }
  std::string name() const override { return "grasper"; }
  std::vector<std::string> coefficient_groups() const override { return {"grasp"}; }
  std::vector<double> coefficients(const std::string& group) const override {
    ForceField::coefficients(group);  // refuses another group
    return {k_};
  }
  std::string coefficient_unit(const std::string&) const override { return "N/m"; }
  std::shared_ptr<const ForceField> scaled(const std::string& group, double factor) const override {
    if (group != "grasp") return ForceField::scaled(group, factor);
    return std::make_shared<Grasper>(num_nodes_, nodes_, point_, k_ * factor, c_);
  }

  void add_force(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                 Eigen::VectorXd& f) const override {
    const Eigen::Vector3d push = -k_ / n() * (mean(x) - point_) - c_ / n() * mean(v);
    for (int i : nodes_)
      f.segment<3>(3 * i) += push;
  }
  double potential_energy(const Eigen::VectorXd& x) const override {
    return 0.5 * k_ * (mean(x) - point_).squaredNorm();
  }
  void add_dfdx_product(const Eigen::VectorXd&, const Eigen::VectorXd&, const Eigen::VectorXd& dx,
                        Eigen::VectorXd& df, Linearisation) const override {
    const Eigen::Vector3d push = -k_ / n() * mean(dx);
    for (int i : nodes_)
      df.segment<3>(3 * i) += push;
  }
  void add_dfdv_product(const Eigen::VectorXd&, const Eigen::VectorXd& dv,
                        Eigen::VectorXd& df) const override {
    const Eigen::Vector3d push = -c_ / n() * mean(dv);
    for (int i : nodes_)
      df.segment<3>(3 * i) += push;
  }
  void add_dfdx_triplets(const Eigen::VectorXd&, const Eigen::VectorXd&, Triplets& t,
                         Linearisation) const override {
    add_coupling(-k_ / (n() * n()), t);
  }
  void add_dfdv_triplets(const Eigen::VectorXd&, Triplets& t) const override {
    add_coupling(-c_ / (n() * n()), t);
  }

 private:
  double n() const { return static_cast<double>(nodes_.size()); }
  Eigen::Vector3d mean(const Eigen::VectorXd& x) const {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int i : nodes_)
      sum += x.segment<3>(3 * i);
    return sum / n();
  }
  void add_coupling(double value, Triplets& t) const {
    for (int i : nodes_)
      for (int j : nodes_)
        for (int d = 0; d < 3; ++d)
          t.emplace_back(3 * i + d, 3 * j + d, value);
  }

  int num_nodes_;
  std::vector<int> nodes_;
  Eigen::Vector3d point_;
  double k_, c_;
};

}  // namespace msfem::massspring::testing
