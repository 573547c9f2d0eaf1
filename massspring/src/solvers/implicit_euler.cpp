// Backward Euler with one linearisation per step (Baraff & Witkin 1998, eq. 16-18):
//   (M - h ∂f/∂v - h² ∂f/∂x) Δv = h (f(x, v) + h ∂f/∂x v),   v' = v + Δv,   x' = x + h v'.
// ∂f/∂x is the definite linearisation, so the matrix is SPD and CG applies (matrix-free).

#include <cmath>
#include <vector>

#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/nodal_load_field.hpp"
#include "msfem/massspring/spring_force_field.hpp"

namespace msfem::massspring {
namespace {

// Diagonal of the system for Jacobi preconditioning: m_i + h (c_i + Σ d_s) + h² Σ k_s over the
// springs at node i (the exact diagonal up to the n nᵀ direction factors, which are <= 1, and
// cheaper than the springs' blocks), and the diagonal of every other field's own blocks of
// -h ∂f/∂v - h² ∂f/∂x.
Eigen::VectorXd jacobi_diagonal(const MechanicalSystem& model, const State& state, double h) {
  const int nodes = model.num_nodes();
  Eigen::VectorXd per_node = model.masses();
  const auto* springs = model.find_field<SpringForceField>();
  if (springs) {
    const SpringNetwork& net = springs->network();
    per_node += h * net.node_damping;
    for (int s = 0; s < net.num_springs(); ++s) {
      const double add = h * net.damping[s] + h * h * net.stiffness[s];
      per_node[net.springs(s, 0)] += add;
      per_node[net.springs(s, 1)] += add;
    }
    for (int a = 0; a < net.num_anchors(); ++a)
      per_node[net.anchor_node[a]] += h * net.anchor_damping[a] + h * h * net.anchor_stiffness[a];
  }
  Eigen::VectorXd diagonal(3 * nodes);
  for (int i = 0; i < nodes; ++i)
    diagonal.segment<3>(3 * i).setConstant(per_node[i]);
  // The nodal loads are constant: no blocks.
  const ForceField* loads = model.find_field<NodalLoadField>();
  std::vector<const ForceField*> others;
  for (const auto& field : model.fields())
    if (field.get() != springs && field.get() != loads) others.push_back(field.get());
  if (others.empty()) return diagonal;
  std::vector<Eigen::Matrix3d> blocks(static_cast<std::size_t>(nodes), Eigen::Matrix3d::Zero());
  for (const ForceField* field : others)
    field->add_diagonal_blocks(state.x, state.v, -h * h, -h, blocks, Linearisation::definite);
  for (int i = 0; i < nodes; ++i)
    diagonal.segment<3>(3 * i) += blocks[static_cast<std::size_t>(i)].diagonal();
  return diagonal;
}

}  // namespace

void Integrator::implicit_euler_step(const MechanicalSystem& model, State& state, double h) {
  const Eigen::VectorXd& x = state.x;
  const Eigen::VectorXd& v = state.v;
  const Eigen::VectorXd mass = model.mass_per_dof();
  const Eigen::Index n = x.size();

  // y = A p on the free dofs (constrained dofs act as identity rows so that they stay zero).
  auto apply = [&](const Eigen::VectorXd& p, Eigen::VectorXd& y) {
    Eigen::VectorXd jacobian_terms = Eigen::VectorXd::Zero(n);
    model.add_dfdx_product(x, v, p, jacobian_terms, Linearisation::definite);
    jacobian_terms *= h;
    model.add_dfdv_product(x, p, jacobian_terms);
    y = mass.cwiseProduct(p) - h * jacobian_terms;
    model.zero_constrained(y);
  };

  Eigen::VectorXd kv = Eigen::VectorXd::Zero(n);
  model.add_dfdx_product(x, v, v, kv, Linearisation::definite);
  Eigen::VectorXd b = h * (model.force(x, v) + h * kv);
  model.zero_constrained(b);

  const Eigen::VectorXd inverse_diagonal = jacobi_diagonal(model, state, h).cwiseInverse();
  Eigen::VectorXd dv =
      previous_dv_.size() == n ? previous_dv_ : Eigen::VectorXd(Eigen::VectorXd::Zero(n));
  model.zero_constrained(dv);
  Eigen::VectorXd r(n), Ap(n);
  apply(dv, Ap);
  r = b - Ap;
  Eigen::VectorXd z = inverse_diagonal.cwiseProduct(r);
  Eigen::VectorXd p = z;
  double rz = r.dot(z);
  const double target = implicit_.cg_tolerance * b.norm();
  int iteration = 0;
  while (iteration < implicit_.cg_max_iterations && r.norm() > target) {
    apply(p, Ap);
    const double pAp = p.dot(Ap);
    if (!(pAp > 0.0)) break;  // breakdown: keep the best iterate so far
    const double alpha = rz / pAp;
    dv += alpha * p;
    r -= alpha * Ap;
    z = inverse_diagonal.cwiseProduct(r);
    const double rz_next = r.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
    ++iteration;
  }
  last_cg_iterations_ = iteration;
  previous_dv_ = dv;
  state.v += dv;
  state.x += h * state.v;
}

}  // namespace msfem::massspring
