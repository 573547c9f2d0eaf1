// The volume field's kept definite tangent (VolumeForceField::tangent): the gradients of one
// linearisation point, kept in the field's lane groups (volume_batches.hpp) so that every product
// of a solve is a vector pass over a group's lanes — a gather, a dot product per lane, a scatter —
// instead of one element at a time.

#include <cmath>
#include <vector>

#include "fields/volume_batches.hpp"
#include "msfem/massspring/volume_force_field.hpp"

namespace msfem::massspring {

// −(κ/|V⁰|) ∂V ∂Vᵀ per element with g = −6 ∂V, so a product is df −= κ/|V⁰| (g·dx)/36 g.
class DefiniteVolumeTangent final : public ForceField::Tangent {
 public:
  DefiniteVolumeTangent(const VolumeForceField& field, const Eigen::VectorXd& x)
      : field_(&field),
        batches_(field.batches_.get()),
        x_(&x),
        g_(3 * batches_->offset.size()),
        scale_(static_cast<std::size_t>(batches_->num_groups()) * L, 0.0),
        pressure_(scale_.size(), 0.0) {}

  // Gradients and volumes of this part's groups; the lanes a group does not fill keep scale 0.
  void set_part(int part, int parts) override {
    const auto& elements = field_->elements_;
    const auto [first, last] = batches_->group_range(part, parts);
    for (int group = first; group < last; ++group) {
      double volume[L];
      detail::group_gradient(*batches_, group, x_->data(), gradient(group), volume);
      for (int l = 0; l < L; ++l) {
        const std::size_t lane = static_cast<std::size_t>(group) * L + l;
        const int e = batches_->element[lane];
        const double rest = elements.rest_volume[e];
        scale_[lane] =
            l < batches_->group_lanes[group] ? elements.modulus[e] / std::abs(rest) : 0.0;
        pressure_[lane] = scale_[lane] * (volume[l] - rest);
      }
    }
  }

  void add_product_part(const Eigen::VectorXd& dx, Eigen::VectorXd& df, int part,
                        int parts) const override {
    for_each_group(part, parts, [&](int group) { add_group_product(group, dx, df); });
  }

  void add_product_pair_part(const Eigen::VectorXd& dx1, Eigen::VectorXd& df1,
                             const Eigen::VectorXd& dx2, Eigen::VectorXd& df2, int part,
                             int parts) const override {
    for_each_group(part, parts, [&](int group) {
      add_group_product(group, dx1, df1);
      add_group_product(group, dx2, df2);
    });
  }

  // The force −κ (V − V⁰)/|V⁰| ∂V = pressure g / 6 from the kept gradients and volumes: the
  // explicit pass's work without its second read of x.
  bool add_force_part(Eigen::VectorXd& f, int part, int parts) const override {
    for_each_group(part, parts, [&](int group) {
      double s[L];
      for (int l = 0; l < L; ++l)
        s[l] = pressure_[static_cast<std::size_t>(group) * L + l] / 6.0;
      detail::scatter_group(*batches_, group, gradient(group), s, f.data());
    });
    return true;
  }

  // The field has no velocity term: cv does not enter. blocks[i] −= cx κ/|V⁰| g_i g_iᵀ / 36.
  void add_diagonal_blocks_part(double cx, double, std::vector<Eigen::Matrix3d>& blocks, int part,
                                int parts) const override {
    for_each_group(part, parts, [&](int group) {
      const double* g = gradient(group);
      const int* offset = batches_->offset.data() + batches_->group_start[group];
      for (int k = 0; k < batches_->nodes(group); ++k)
        for (int l = 0; l < batches_->group_lanes[group]; ++l) {
          const double c = cx * scale_[static_cast<std::size_t>(group) * L + l] / 36.0;
          const Eigen::Vector3d gk(g[3 * k * L + l], g[(3 * k + 1) * L + l],
                                   g[(3 * k + 2) * L + l]);
          blocks[static_cast<std::size_t>(offset[k * L + l] / 3)].noalias() -=
              c * gk * gk.transpose();
        }
    });
  }

 private:
  static constexpr int L = detail::kVolumeLanes;

  // df −= κ/|V⁰| (g·dx)/36 g over the group's lanes.
  void add_group_product(int group, const Eigen::VectorXd& dx, Eigen::VectorXd& df) const {
    const double* g = gradient(group);
    double s[L];
    detail::group_dot(*batches_, group, g, dx.data(), s);
    for (int l = 0; l < L; ++l)
      s[l] *= -scale_[static_cast<std::size_t>(group) * L + l] / 36.0;
    detail::scatter_group(*batches_, group, g, s, df.data());
  }
  // The groups of part `part` of `parts`: set_part's, so that a thread reads only the gradients
  // it wrote itself.
  template <class Visit>
  void for_each_group(int part, int parts, const Visit& visit) const {
    const auto [first, last] = batches_->group_range(part, parts);
    for (int group = first; group < last; ++group)
      visit(group);
  }
  double* gradient(int group) { return g_.data() + 3 * batches_->group_start[group]; }
  const double* gradient(int group) const { return g_.data() + 3 * batches_->group_start[group]; }

  const VolumeForceField* field_;
  const detail::VolumeBatches* batches_;
  const Eigen::VectorXd* x_;
  std::vector<double> g_;         // per group, g[(3k + c)·L + l] (group_gradient's layout)
  std::vector<double> scale_;     // per group lane: κ/|V⁰|, 0 on lanes the group does not fill
  std::vector<double> pressure_;  // per group lane: κ (V − V⁰)/|V⁰| at set_part
};

std::unique_ptr<ForceField::Tangent> VolumeForceField::tangent(const Eigen::VectorXd& x,
                                                               const Eigen::VectorXd& v,
                                                               Linearisation mode) const {
  if (mode == Linearisation::exact) return ForceField::tangent(x, v, mode);
  return std::make_unique<DefiniteVolumeTangent>(*this, x);
}

}  // namespace msfem::massspring
