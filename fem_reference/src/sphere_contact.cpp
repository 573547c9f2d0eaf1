// Frictionless contact with rigid spheres (SphereObstacle): the active-set iteration around the
// linear solve of elasticity_problem.cpp.

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "elasticity_problem_impl.hpp"
#include "msfem/fem_reference/errors.hpp"
#include "petsc_linear_system.hpp"

namespace msfem::fem_reference {

using namespace dealii;

namespace {

constexpr int dim = 3;
/// Relative tolerance of the solves that search for the active set.
constexpr double loose_tolerance = 1e-6;

/// A boundary node that may touch an obstacle, owned by this rank.
struct Candidate {
  std::size_t obstacle;
  std::size_t first_dof;
  double penalty;  ///< N/m
};

/// The active-set iteration: for the nodes inside a sphere at the present iterate, the normal
/// penalty spring that closes the linearised gap; solve; repeat until the set repeats.
class ActiveSetIteration {
 public:
  explicit ActiveSetIteration(ElasticityProblem::Implementation& problem) : p_(problem) {}

  detail::KrylovReport run(const std::vector<double>& coordinates) {
    collect_candidates();
    std::vector<double> u = initial_displacement();
    std::vector<char> active = active_flags(u);
    if (p_.model.initial_displacement) {
      p_.linear_system->set_start(u);
    } else {
      start_at_hertz_radius(active);
      push_out_along_axis(active, u);
    }
    std::vector<std::vector<char>> history{active};
    detail::KrylovReport total;
    const int max_iterations = max_allowed_iterations();
    // Inexact Newton: the active set is found with loose solves (from the last solution, a few
    // Krylov iterations each); once it repeats, one solve to the case's tolerance confirms it.
    SolverSettings loose = p_.model.solver;
    loose.relative_tolerance = std::max(loose.relative_tolerance, loose_tolerance);
    bool accurate = false;
    for (int iteration = 1;; ++iteration) {
      set_penalties(active, u);
      const detail::KrylovReport report =
          p_.linear_system->solve(accurate ? p_.model.solver : loose, coordinates);
      total.iterations += report.iterations;
      total.residual_norm = report.residual_norm;
      u = p_.linear_system->gathered_solution();
      const std::vector<char> next = active_flags(u);
      if (globally_equal(next, active)) {
        if (accurate) {
          finish(u, iteration);
          return total;
        }
        accurate = true;
        continue;
      }
      std::vector<char> following = next;
      for (std::size_t j = 0; j + 1 < history.size(); ++j)
        if (globally_equal(next, history[j])) {
          // A few edge nodes can still alternate (their gap changes sign with their neighbours'
          // state). The first time, the switching nodes are held in contact for good: each pulls
          // at most its penalty times a gap of the order of the band. A second cycle is an error.
          if (holding_) throw cycling(active, next, iteration);
          hold_switching_nodes(active, following);
          break;
        }
      if (iteration >= max_iterations) throw not_settled(active, following, iteration);
      history.push_back(following);
      active = following;
    }
  }

 private:
  const SphereObstacle& obstacle(const Candidate& c) const {
    return p_.model.obstacles[c.obstacle];
  }
  Eigen::Vector3d reference_position(std::size_t dof) const {
    return to_eigen(p_.dof_support_points[dof]);
  }
  static Eigen::Vector3d node_value(const std::vector<double>& u, std::size_t dof) {
    return {u[dof], u[dof + 1], u[dof + 2]};
  }
  bool prescribed(std::size_t dof) const { return p_.dof_support[dof] >= 0; }

  int max_allowed_iterations() const {
    int n = 1;
    for (const SphereObstacle& o : p_.model.obstacles)
      n = std::max(n, o.max_iterations);
    return n;
  }

  /// Owned boundary nodes in each obstacle's candidate region with a free component; the penalty
  /// scaled by the node's mean diagonal stiffness over its free components.
  void collect_candidates() {
    const std::vector<double> diagonal = p_.linear_system->owned_diagonal();
    const IndexSet owned = p_.dof_handler.locally_owned_dofs();
    const std::size_t first = owned.n_elements() > 0 ? owned.nth_index_in_set(0) : 0;
    const std::size_t end = first + owned.n_elements();
    std::vector<long> caught(p_.model.obstacles.size(), 0);
    for (std::size_t o = 0; o < p_.model.obstacles.size(); ++o) {
      const SphereObstacle& obstacle = p_.model.obstacles[o];
      for (std::size_t dof = first; dof < end; dof += dim) {
        if (!p_.dof_on_boundary[dof]) continue;
        if (obstacle.candidates && !obstacle.candidates(reference_position(dof))) continue;
        double sum = 0.0;
        int free = 0;
        for (int c = 0; c < dim; ++c)
          if (!prescribed(dof + c)) sum += diagonal[dof + c - first], ++free;
        if (free == 0) continue;
        candidates_.push_back({o, dof, obstacle.penalty_factor * sum / free});
        ++caught[o];
      }
    }
    for (std::size_t o = 0; o < caught.size(); ++o)
      if (Utilities::MPI::sum(caught[o], p_.communicator) == 0)
        throw std::invalid_argument("obstacle '" + p_.model.obstacles[o].name +
                                    "' has no free boundary node among its candidates");
  }

  /// The prescribed values, and the model's guess (or zero) elsewhere.
  std::vector<double> initial_displacement() const {
    std::vector<double> u(p_.dof_handler.n_dofs(), 0.0);
    const auto& guess = p_.model.initial_displacement;
    for (std::size_t dof = 0; dof < u.size(); dof += dim) {
      const Eigen::Vector3d g = guess ? guess(reference_position(dof)) : Eigen::Vector3d::Zero();
      for (int c = 0; c < dim; ++c)
        u[dof + c] = prescribed(dof + c) ? p_.prescribed_value[dof + c] : g[c];
    }
    return u;
  }

  double axis_distance(const Candidate& c) const {
    const Eigen::Vector3d e = obstacle(c).push_direction.normalized();
    const Eigen::Vector3d w = reference_position(c.first_dof) - obstacle(c).center;
    return (w - w.dot(e) * e).norm();
  }

  /// The first active set: of the nodes the sphere overlaps (out to radius c from its axis), those
  /// within c / sqrt(2), Hertz's contact radius sqrt(R d) against the overlap's sqrt(2 R d). From
  /// the whole overlap the iteration first releases about half the nodes and then takes some back;
  /// from here it needs about half the iterations.
  void start_at_hertz_radius(std::vector<char>& active) const {
    std::vector<double> overlap(p_.model.obstacles.size(), 0.0);
    for (std::size_t k = 0; k < candidates_.size(); ++k)
      if (active[k])
        overlap[candidates_[k].obstacle] =
            std::max(overlap[candidates_[k].obstacle], axis_distance(candidates_[k]));
    for (double& c : overlap)
      c = Utilities::MPI::max(c, p_.communicator);
    for (std::size_t k = 0; k < candidates_.size(); ++k)
      if (active[k] && axis_distance(candidates_[k]) > overlap[candidates_[k].obstacle] / M_SQRT2)
        active[k] = 0;
  }

  /// The first linearisation: each node inside a sphere taken to where the sphere, pushed in
  /// along its axis, would have carried it (onto its far side along the axis), so that its normal
  /// points into the body as the tool's does. Normals from the rest positions would point sideways
  /// near the axis of a deep press and push the surface apart.
  void push_out_along_axis(const std::vector<char>& active, std::vector<double>& u) const {
    for (std::size_t k = 0; k < candidates_.size(); ++k) {
      if (!active[k]) continue;
      const Candidate& c = candidates_[k];
      const Eigen::Vector3d e = obstacle(c).push_direction.normalized();
      const Eigen::Vector3d w = reference_position(c.first_dof) - obstacle(c).center;
      const double b = e.dot(w), r = obstacle(c).radius;
      // The larger root of |w + t e| = r.
      const double t = -b + std::sqrt(std::max(0.0, b * b + r * r - w.squaredNorm()));
      for (int a = 0; a < dim; ++a)
        if (!prescribed(c.first_dof + a)) u[c.first_dof + a] += t * e[a];
    }
  }

  /// Signed distance of the node's present position from the sphere's surface (negative inside).
  double gap(const Candidate& c, const std::vector<double>& u) const {
    const Eigen::Vector3d x = reference_position(c.first_dof) + node_value(u, c.first_dof);
    return (x - obstacle(c).center).norm() - obstacle(c).radius;
  }

  /// The nodes inside a sphere at u. A node that was active is judged by the gap the linear system
  /// saw, n . u - t along its normal: the true gap also grows by |tangential motion|^2 / 2R since
  /// the normal was taken, which after the first solve exceeds the penalty's penetration by orders
  /// of magnitude and would release the whole contact; at the fixed point the two agree.
  void hold_switching_nodes(const std::vector<char>& active, std::vector<char>& next) {
    held_.assign(candidates_.size(), 0);
    for (std::size_t k = 0; k < candidates_.size(); ++k)
      if (active[k] != next[k]) held_[k] = next[k] = 1;
    holding_ = true;
  }

  /// A node changes state only when its gap is beyond a band of a hundredth of the deepest
  /// penetration: nodes at the edge of the contact, whose gap is within the solver's error of
  /// zero, would otherwise flip in and out for ever. A node kept in contact may pull, or one kept
  /// out may enter, by that band: a hundredth of a node's contact force.
  std::vector<char> active_flags(const std::vector<double>& u) const {
    // Before any set: the guess's deepest node (a cold start's overlap never decides by the band).
    double deepest = 0.0;
    if (active_.empty() && p_.model.initial_displacement)
      for (std::size_t k = 0; k < candidates_.size(); ++k)
        deepest = std::max(deepest, -gap(candidates_[k], u));
    for (std::size_t k = 0; k < active_.size(); ++k)
      if (active_[k])
        deepest = std::max(deepest,
                           targets_[k] - normals_[k].dot(node_value(u, candidates_[k].first_dof)));
    const double band = 1e-2 * Utilities::MPI::max(deepest, p_.communicator);
    std::vector<char> flags(candidates_.size(), 0);
    for (std::size_t k = 0; k < candidates_.size(); ++k) {
      if (holding_ && held_[k]) {
        flags[k] = 1;
        continue;
      }
      const bool was_active = k < active_.size() && active_[k];
      const double g = was_active
                           ? normals_[k].dot(node_value(u, candidates_[k].first_dof)) - targets_[k]
                           : gap(candidates_[k], u);
      flags[k] = was_active ? g < band : g < -band;
    }
    return flags;
  }

  bool globally_equal(const std::vector<char>& a, const std::vector<char>& b) const {
    return Utilities::MPI::min(int(a == b), p_.communicator) == 1;
  }

  /// The linearised gap condition n . u = t at the present iterate u0: n the sphere's outward
  /// normal at the node's present position, t = n . u0 - gap(u0).
  void normal_and_target(const Candidate& c, const std::vector<double>& u, Eigen::Vector3d& n,
                         double& t) const {
    const Eigen::Vector3d u0 = node_value(u, c.first_dof);
    const Eigen::Vector3d w = reference_position(c.first_dof) + u0 - obstacle(c).center;
    const double rho = w.norm();
    // A node exactly at the centre leaves the sphere along its axis, into the body.
    n = rho > 0.0 ? Eigen::Vector3d(w / rho)
                  : Eigen::Vector3d(obstacle(c).push_direction.normalized());
    t = n.dot(u0) - (rho - obstacle(c).radius);
  }

  /// The energy k/2 (n . u - t)^2 over the free components (prescribed ones moved to the rhs).
  void set_penalties(const std::vector<char>& active, const std::vector<double>& u) {
    std::vector<PetscInt> rows;
    std::vector<std::array<double, 9>> blocks;
    std::vector<std::array<double, 3>> rhs;
    normals_.assign(candidates_.size(), Eigen::Vector3d::Zero());
    targets_.assign(candidates_.size(), 0.0);
    for (std::size_t k = 0; k < candidates_.size(); ++k) {
      if (!active[k]) continue;
      const Candidate& c = candidates_[k];
      normal_and_target(c, u, normals_[k], targets_[k]);
      const Eigen::Vector3d& n = normals_[k];
      double fixed_part = 0.0;
      for (int a = 0; a < dim; ++a)
        if (prescribed(c.first_dof + a)) fixed_part += n[a] * p_.prescribed_value[c.first_dof + a];
      std::array<double, 9> block{};
      std::array<double, 3> load{};
      for (int a = 0; a < dim; ++a) {
        if (prescribed(c.first_dof + a)) continue;
        load[a] = c.penalty * n[a] * (targets_[k] - fixed_part);
        for (int b = 0; b < dim; ++b)
          if (!prescribed(c.first_dof + b)) block[a * dim + b] = c.penalty * n[a] * n[b];
      }
      rows.push_back(PetscInt(c.first_dof));
      blocks.push_back(block);
      rhs.push_back(load);
    }
    p_.linear_system->set_node_terms(rows, blocks, rhs);
    active_ = active;
  }

  /// Per obstacle: the force k (t - n . u) n summed over its active nodes, the contact radius, the
  /// penetration; and each owned DoF's contact force for the supports' reactions.
  void finish(const std::vector<double>& u, int iterations) {
    const std::size_t count = p_.model.obstacles.size();
    std::vector<Eigen::Vector3d> force(count, Eigen::Vector3d::Zero());
    std::vector<double> moment0(count, 0.0), moment2(count, 0.0), outermost(count, 0.0),
        penetration(count, 0.0), active_nodes(count, 0.0);
    for (std::size_t k = 0; k < candidates_.size(); ++k) {
      if (!active_[k]) continue;
      const Candidate& c = candidates_[k];
      const std::size_t o = c.obstacle;
      const double magnitude =
          c.penalty * (targets_[k] - normals_[k].dot(node_value(u, c.first_dof)));
      const Eigen::Vector3d f = magnitude * normals_[k];
      force[o] += f;
      for (int a = 0; a < dim; ++a)
        p_.contact_dof_force.emplace_back(c.first_dof + a, f[a]);
      const double r2 = std::pow(axis_distance(c), 2);
      moment0[o] += magnitude;
      moment2[o] += magnitude * r2;
      outermost[o] = std::max(outermost[o], std::sqrt(r2));
      penetration[o] = std::max(penetration[o], -gap(c, u));
      active_nodes[o] += 1;
    }
    p_.contact_reports.assign(count, ContactReport());
    for (std::size_t o = 0; o < count; ++o) {
      ContactReport& r = p_.contact_reports[o];
      for (int a = 0; a < dim; ++a)
        r.force[a] = Utilities::MPI::sum(force[o][a], p_.communicator);
      const double m0 = Utilities::MPI::sum(moment0[o], p_.communicator);
      const double m2 = Utilities::MPI::sum(moment2[o], p_.communicator);
      r.contact_radius = m0 > 0.0 ? std::sqrt(2.5 * m2 / m0) : 0.0;
      r.outermost_node_radius = Utilities::MPI::max(outermost[o], p_.communicator);
      r.max_penetration = Utilities::MPI::max(penetration[o], p_.communicator);
      r.active_nodes = int(Utilities::MPI::sum(active_nodes[o], p_.communicator));
      r.iterations = iterations;
    }
  }

  /// The nodes whose state differs between two sets: how many (all ranks) and where a few are.
  std::string switching_nodes(const std::vector<char>& a, const std::vector<char>& b) const {
    std::ostringstream where;
    long switching = 0;
    for (std::size_t k = 0; k < candidates_.size(); ++k) {
      if (a[k] == b[k]) continue;
      if (switching < 4) {
        const Eigen::Vector3d x = reference_position(candidates_[k].first_dof);
        where << (switching ? ", " : "") << "(" << x.x() << ", " << x.y() << ", " << x.z() << ")";
      }
      ++switching;
    }
    const long all = Utilities::MPI::sum(switching, p_.communicator);
    return std::to_string(all) + " node(s) switching, e.g. at " + where.str() + " m";
  }

  std::string names() const {
    std::string result;
    for (const SphereObstacle& o : p_.model.obstacles)
      result += (result.empty() ? "'" : ", '") + o.name + "'";
    return result;
  }

  FemError cycling(const std::vector<char>& a, const std::vector<char>& b, int iteration) const {
    return FemError("contact with " + names() + " does not converge: the active set cycles after " +
                    std::to_string(iteration) + " iterations; " + switching_nodes(a, b));
  }

  FemError not_settled(const std::vector<char>& a, const std::vector<char>& b,
                       int iteration) const {
    return FemError("contact with " + names() + " did not settle in " + std::to_string(iteration) +
                    " active-set iterations; " + switching_nodes(a, b));
  }

  ElasticityProblem::Implementation& p_;
  std::vector<Candidate> candidates_;
  std::vector<char> active_;
  std::vector<char> held_;  ///< nodes kept in contact after a cycle
  bool holding_ = false;    ///< on every rank once any rank saw the cycle (the test is global)
  std::vector<Eigen::Vector3d> normals_;
  std::vector<double> targets_;
};

}  // namespace

detail::KrylovReport ElasticityProblem::Implementation::solve_with_contact(
    const std::vector<double>& coordinates) {
  linear_system->keep_base_system();
  return ActiveSetIteration(*this).run(coordinates);
}

ContactReport ElasticityProblem::contact(const std::string& obstacle_name) const {
  if (!impl_->solved) throw std::logic_error("contact() before run()");
  for (std::size_t o = 0; o < impl_->model.obstacles.size(); ++o)
    if (impl_->model.obstacles[o].name == obstacle_name) return impl_->contact_reports[o];
  throw std::invalid_argument("no obstacle named '" + obstacle_name + "'");
}

}  // namespace msfem::fem_reference
