#include "msfem/massspring/force_model.hpp"

#include <algorithm>

#include "msfem/massspring/errors.hpp"

namespace msfem::massspring {

std::shared_ptr<const ForceField> ForceField::scaled(const std::string& group, double) const {
  throw ModelError(name() + ": no coefficient group '" + group + "' to scale");
}

std::vector<double> ForceField::coefficients(const std::string& group) const {
  const std::vector<std::string> groups = coefficient_groups();
  if (std::find(groups.begin(), groups.end(), group) == groups.end())
    throw ModelError(name() + ": no coefficient group '" + group + "'");
  return {1.0};
}

namespace {

class RecomputedTangent final : public ForceField::Tangent {
 public:
  RecomputedTangent(const ForceField& field, const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                    Linearisation mode)
      : field_(&field), x_(&x), v_(&v), mode_(mode) {}
  void set_part(int, int) override {}
  void add_product_part(const Eigen::VectorXd& dx, Eigen::VectorXd& df, int part,
                        int parts) const override {
    field_->add_dfdx_product_part(*x_, *v_, dx, df, mode_, part, parts);
  }
  void add_diagonal_blocks_part(double cx, double cv, std::vector<Eigen::Matrix3d>& blocks,
                                int part, int) const override {
    if (part == 0) field_->add_diagonal_blocks(*x_, *v_, cx, cv, blocks, mode_);
  }

 private:
  const ForceField* field_;
  const Eigen::VectorXd *x_, *v_;
  Linearisation mode_;
};

}  // namespace

std::unique_ptr<ForceField::Tangent> ForceField::tangent(const Eigen::VectorXd& x,
                                                         const Eigen::VectorXd& v,
                                                         Linearisation mode) const {
  return std::make_unique<RecomputedTangent>(*this, x, v, mode);
}

void ForceField::add_diagonal_blocks(const Eigen::VectorXd& x, const Eigen::VectorXd& v, double cx,
                                     double cv, std::vector<Eigen::Matrix3d>& blocks,
                                     Linearisation mode) const {
  Triplets dfdx_terms, dfdv_terms;
  add_dfdx_triplets(x, v, dfdx_terms, mode);
  add_dfdv_triplets(x, dfdv_terms);
  auto add = [&](const Triplets& terms, double scale) {
    for (const auto& t : terms)
      if (t.row() / 3 == t.col() / 3)
        blocks[static_cast<std::size_t>(t.row() / 3)](t.row() % 3, t.col() % 3) +=
            scale * t.value();
  };
  add(dfdx_terms, cx);
  add(dfdv_terms, cv);
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
