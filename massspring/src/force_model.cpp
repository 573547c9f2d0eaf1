#include "msfem/massspring/force_model.hpp"

#include "msfem/massspring/errors.hpp"

namespace msfem::massspring {

std::shared_ptr<const ForceField> ForceField::scaled(const std::string& group, double) const {
  throw ModelError("force field: no coefficient group '" + group + "' to scale");
}

Eigen::VectorXd ForceModel::force(const Eigen::VectorXd& x, const Eigen::VectorXd& v) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(num_dofs());
  add_force(x, v, f);
  return f;
}

Eigen::SparseMatrix<double> ForceModel::dfdx(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                                             Linearisation mode) const {
  Triplets triplets;
  add_dfdx_triplets(x, v, triplets, mode);
  Eigen::SparseMatrix<double> matrix(num_dofs(), num_dofs());
  matrix.setFromTriplets(triplets.begin(), triplets.end());
  return matrix;
}

Eigen::SparseMatrix<double> ForceModel::dfdv(const Eigen::VectorXd& x) const {
  Triplets triplets;
  add_dfdv_triplets(x, triplets);
  Eigen::SparseMatrix<double> matrix(num_dofs(), num_dofs());
  matrix.setFromTriplets(triplets.begin(), triplets.end());
  return matrix;
}

}  // namespace msfem::massspring
