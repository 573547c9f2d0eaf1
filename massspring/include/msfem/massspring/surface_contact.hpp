#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "msfem/massspring/tool_contact.hpp"

namespace msfem::massspring {

class MassSpringModel;

/// Frictionless contact of a rigid sphere with the surface's triangles, so that a tool smaller than
/// the cells, or pressed between nodes, is still felt. A pressure penalty over the surface:
///   U = ½ κ ∫_S max(0, r - |x(s) - c|)² dA_rest,
/// pressure p = κ (r - ρ) along the sphere's normal at each point, the point's force shared among
/// its triangle's nodes by barycentric weights. The integral is taken at the centroids of a
/// uniform n x n subdivision of each triangle, with n from its rest edge (at most a sixth of the
/// tool's radius per sub-edge), so the contact is resolved whatever the mesh. Energy, force and
/// Jacobians are those of that quadrature exactly (checked by finite differences). The broad phase
/// is a k-d tree over the rest triangles' centroids (nanoflann), queried per call with the tool's
/// radius plus the largest triangle and the largest surface displacement.
class SurfaceContactForceField : public ToolContact {
 public:
  /// `rest_positions` n x 3 (m), `triangles` in node ids; κ = `pressure_penalty` in Pa/m.
  SurfaceContactForceField(const Eigen::MatrixX3d& rest_positions, Eigen::MatrixX3i triangles,
                           SphereTool tool, double pressure_penalty);

  int num_dofs() const override { return 3 * num_nodes_; }
  void add_force(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                 Eigen::VectorXd& f) const override;
  double potential_energy(const Eigen::VectorXd& x) const override;
  void add_dfdx_product(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                        const Eigen::VectorXd& dx, Eigen::VectorXd& df,
                        Linearisation mode = Linearisation::exact) const override;
  void add_dfdx_triplets(const Eigen::VectorXd& x, const Eigen::VectorXd& v, Triplets& triplets,
                         Linearisation mode = Linearisation::exact) const override;
  /// Parts take every parts-th triangle the broad phase finds near the tool.
  void add_force_part(const Eigen::VectorXd& x, const Eigen::VectorXd& v, Eigen::VectorXd& f,
                      int part, int parts) const override;
  void add_dfdx_product_part(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                             const Eigen::VectorXd& dx, Eigen::VectorXd& df, Linearisation mode,
                             int part, int parts) const override;
  /// The contact points found once per set_part, each with its force and stiffness block: a
  /// product is a pass over the points inside the tool, not a new search of the sub-triangles.
  std::unique_ptr<Tangent> tangent(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                                   Linearisation mode) const override;

  const SphereTool& tool() const override { return tool_; }
  const std::vector<int>& nodes() const override { return nodes_; }
  std::string name() const override { return "tool contact (surface)"; }
  double penalty_stiffness() const override { return pressure_penalty_ * mean_node_area_; }
  std::shared_ptr<ToolContact> clone() const override {
    return std::make_shared<SurfaceContactForceField>(*this);  // shares the rest-state k-d tree
  }
  void move_tool(const Eigen::Vector3d& center) override { tool_.center = center; }
  double pressure_penalty() const { return pressure_penalty_; }
  /// κ (Pa/m), finite and > 0 (ModelError otherwise).
  void set_pressure_penalty(double pressure_penalty);

  /// The contact area (m², rest measure) and the number of triangles touched at x.
  double contact_area(const Eigen::VectorXd& x) const;

  struct BroadPhase;  ///< the k-d tree (defined in the source)

 private:
  friend class KeptContactTangent;
  /// Calls `visit(triangle, b0, b1, b2, coefficient, w)` for every quadrature point inside the
  /// sphere, coefficient = κ A weight, w = x(s) - c, on part `part` of `parts` of the triangles
  /// near the tool (every parts-th, so that the touched ones spread over the parts).
  template <class Visit>
  void for_each_contact_point(const Eigen::VectorXd& x, Visit&& visit, int part = 0,
                              int parts = 1) const;
  Eigen::Matrix3d block(const Eigen::Vector3d& w, Linearisation mode) const;

  int num_nodes_;
  Eigen::MatrixX3d rest_positions_;
  Eigen::MatrixX3i triangles_;
  std::vector<double> rest_area_;
  std::vector<int> subdivisions_;
  std::vector<int> nodes_;
  SphereTool tool_;
  double pressure_penalty_;
  double mean_node_area_ = 0.0;
  double largest_triangle_radius_ = 0.0;
  std::shared_ptr<const BroadPhase> broad_phase_;
};

/// Activates the surface contact of the tool at full depth with the model's surface triangles.
/// pressure_penalty <= 0 picks 1000 x the stiffest surface node's summed stiffness over a mean
/// surface node's area. Returns the pressure penalty used (Pa/m).
double activate_surface_contact(MassSpringModel& model, const ToolIndentation& indent,
                                double pressure_penalty = 0.0);

}  // namespace msfem::massspring
