// Backward Euler with matrix-free CG on the structure-of-arrays layout (fast_implicit_stepper.hpp).

#include "msfem/massspring/fast_implicit_stepper.hpp"

#include <algorithm>
#include <cmath>

#include "soa_layout.hpp"
#include "thread_team.hpp"

namespace msfem::massspring {

class FastImplicitStepper::Implementation {
 public:
  Implementation(const MassSpringModel& model, const FastImplicitOptions& options)
      : model_(&model),
        options_(options),
        team_(std::max(options.threads, 1)),
        soa_(model, options.reorder_nodes, team_.size()) {
    const int s = soa_.num_springs, n = soa_.num_nodes;
    for (int c = 0; c < 3; ++c) {
      normal_[c].assign(s, 0.0);
      spring_vector_[c].assign(s, 0.0);
      rhs_[c].assign(n, 0.0);
      dv_[c].assign(n, 0.0);
      residual_[c].assign(n, 0.0);
      direction_[c].assign(n, 0.0);  // zero on constrained nodes, always
      product_[c].assign(n, 0.0);
      preconditioned_[c].assign(n, 0.0);
      inverse_diagonal_[c].assign(n, 0.0);
    }
    alpha_.assign(s, 0.0);
    beta_.assign(s, 0.0);
    partial_.assign(3 * team_.size(), 0.0);
  }

  const MassSpringModel* model_;
  FastImplicitOptions options_;
  detail::ThreadTeam team_;
  detail::SoaLayout<double> soa_;
  double time_ = 0.0;
  int last_iterations_ = 0;

  void step(double h) {
    check_time_step(h);
    int iterations = 0;
    const std::function<void(int)> job = [&](int member) {
      const int s0 = soa_.spring_begin[member], s1 = soa_.spring_begin[member + 1];
      const int n0 = soa_.node_begin[member], n1 = soa_.node_begin[member + 1];
      linearise(s0, s1, h);
      team_.barrier();
      assemble_rhs_and_diagonal(n0, n1, h);
      // Warm start: r = b - A Δv_previous.
      copy(dv_, direction_, n0, n1);
      team_.barrier();
      product_springs(s0, s1);
      team_.barrier();
      double rz = 0.0, rr = 0.0, bb = 0.0;
      product_nodes(n0, n1, h);
      {
        double local_rz = 0.0, local_rr = 0.0, local_bb = 0.0;
        for (int i = n0; i < n1; ++i)
          for (int c = 0; c < 3; ++c) {
            residual_[c][i] = rhs_[c][i] - product_[c][i];
            preconditioned_[c][i] = inverse_diagonal_[c][i] * residual_[c][i];
            direction_[c][i] = preconditioned_[c][i];
            local_rz += residual_[c][i] * preconditioned_[c][i];
            local_rr += residual_[c][i] * residual_[c][i];
            local_bb += rhs_[c][i] * rhs_[c][i];
          }
        reduce(member, local_rz, local_rr, local_bb, rz, rr, bb);
      }
      const double target = options_.cg_tolerance * options_.cg_tolerance * bb;
      int iteration = 0;
      while (iteration < options_.cg_max_iterations && rr > target) {
        product_springs(s0, s1);
        team_.barrier();
        product_nodes(n0, n1, h);
        double local_pap = 0.0;
        for (int i = n0; i < n1; ++i)
          for (int c = 0; c < 3; ++c)
            local_pap += direction_[c][i] * product_[c][i];
        double pap = 0.0, unused1 = 0.0, unused2 = 0.0;
        reduce(member, local_pap, 0.0, 0.0, pap, unused1, unused2);
        if (!(pap > 0.0)) break;
        const double step_length = rz / pap;
        double local_rz = 0.0, local_rr = 0.0;
        for (int i = n0; i < n1; ++i)
          for (int c = 0; c < 3; ++c) {
            dv_[c][i] += step_length * direction_[c][i];
            residual_[c][i] -= step_length * product_[c][i];
            preconditioned_[c][i] = inverse_diagonal_[c][i] * residual_[c][i];
            local_rz += residual_[c][i] * preconditioned_[c][i];
            local_rr += residual_[c][i] * residual_[c][i];
          }
        double rz_next = 0.0;
        reduce(member, local_rz, local_rr, 0.0, rz_next, rr, unused2);
        const double ratio = rz_next / rz;
        rz = rz_next;
        for (int i = n0; i < n1; ++i)
          for (int c = 0; c < 3; ++c)
            direction_[c][i] = preconditioned_[c][i] + ratio * direction_[c][i];
        team_.barrier();  // directions complete before the next spring pass reads them
        ++iteration;
      }
      // v += Δv, x += h v on the free nodes.
      for (int i = n0; i < n1; ++i)
        for (int c = 0; c < 3; ++c) {
          soa_.v[c][i] += dv_[c][i];
          soa_.x[c][i] += h * soa_.v[c][i];
        }
      if (member == 0) iterations = iteration;
    };
    team_.run(job);
    last_iterations_ = iterations;
    time_ += h;
  }

 private:
  // Per spring: the force (into spring_vector_), n, and the coefficients α, β of the system block,
  // plus h K_s w for the right-hand side (added to spring_vector_).
  void linearise(int begin, int end, double h) {
    for (int s = begin; s < end; ++s) {
      const int i = soa_.a[s], j = soa_.b[s];
      double d[3], w[3];
      for (int c = 0; c < 3; ++c) {
        d[c] = soa_.x[c][j] - soa_.x[c][i];
        w[c] = soa_.v[c][j] - soa_.v[c][i];
      }
      const double length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      const double n[3] = {d[0] / length, d[1] / length, d[2] / length};
      const double n_w = n[0] * w[0] + n[1] * w[1] + n[2] * w[2];
      const double k = soa_.stiffness[s];
      const double tau = std::max(0.0, 1.0 - soa_.rest_length[s] / length);
      const double force = k * (length - soa_.rest_length[s]) + soa_.damping[s] * n_w;
      alpha_[s] = h * h * k * tau;
      beta_[s] = h * soa_.damping[s] + h * h * k * (1.0 - tau);
      // f_s + h K_s w, K_s w = k τ w + k (1 - τ)(n·w) n
      for (int c = 0; c < 3; ++c) {
        normal_[c][s] = n[c];
        spring_vector_[c][s] = force * n[c] + h * (k * tau * w[c] + k * (1.0 - tau) * n_w * n[c]);
      }
    }
  }

  // b = h (F + h K v) and the exact diagonal of M - hD - h²K, per free node.
  void assemble_rhs_and_diagonal(int begin, int end, double h) {
    for (int i = begin; i < end; ++i) {
      const double anchor = soa_.anchor_stiffness[i];
      const double damping = soa_.node_damping[i];
      double sum[3] = {0.0, 0.0, 0.0};
      double diagonal[3];
      for (int c = 0; c < 3; ++c)
        diagonal[c] = soa_.mass[i] + h * damping + h * h * anchor;
      for (int e = soa_.offset[i]; e < soa_.offset[i + 1]; ++e) {
        const int s = soa_.incident[e];
        for (int c = 0; c < 3; ++c) {
          sum[c] += soa_.sign[e] * spring_vector_[c][s];
          diagonal[c] += alpha_[s] + beta_[s] * normal_[c][s] * normal_[c][s];
        }
      }
      for (int c = 0; c < 3; ++c) {
        const double force = soa_.load[c][i] - damping * soa_.v[c][i] - anchor * soa_.x[c][i] +
                             sum[c] - h * anchor * soa_.v[c][i];
        rhs_[c][i] = h * force;
        inverse_diagonal_[c][i] = 1.0 / diagonal[c];
      }
    }
  }

  // y_s = α q + β (n·q) n with q = p_b - p_a.
  void product_springs(int begin, int end) {
    for (int s = begin; s < end; ++s) {
      const int i = soa_.a[s], j = soa_.b[s];
      const double qx = direction_[0][j] - direction_[0][i];
      const double qy = direction_[1][j] - direction_[1][i];
      const double qz = direction_[2][j] - direction_[2][i];
      const double projected =
          beta_[s] * (normal_[0][s] * qx + normal_[1][s] * qy + normal_[2][s] * qz);
      spring_vector_[0][s] = alpha_[s] * qx + projected * normal_[0][s];
      spring_vector_[1][s] = alpha_[s] * qy + projected * normal_[1][s];
      spring_vector_[2][s] = alpha_[s] * qz + projected * normal_[2][s];
    }
  }

  // (A p)_i = (m + h c + h² k_a) p_i - Σ sign y_s.
  void product_nodes(int begin, int end, double h) {
    for (int i = begin; i < end; ++i) {
      const double own = soa_.mass[i] + h * soa_.node_damping[i] + h * h * soa_.anchor_stiffness[i];
      double sum[3] = {0.0, 0.0, 0.0};
      for (int e = soa_.offset[i]; e < soa_.offset[i + 1]; ++e) {
        const int s = soa_.incident[e];
        for (int c = 0; c < 3; ++c)
          sum[c] += soa_.sign[e] * spring_vector_[c][s];
      }
      for (int c = 0; c < 3; ++c)
        product_[c][i] = own * direction_[c][i] - sum[c];
    }
  }

  static void copy(const std::vector<double> (&from)[3], std::vector<double> (&to)[3], int begin,
                   int end) {
    for (int c = 0; c < 3; ++c)
      std::copy(from[c].begin() + begin, from[c].begin() + end, to[c].begin() + begin);
  }

  // Sums three per-member values over the team; every member gets the same totals.
  void reduce(int member, double a, double b, double c, double& sum_a, double& sum_b,
              double& sum_c) {
    partial_[3 * member] = a;
    partial_[3 * member + 1] = b;
    partial_[3 * member + 2] = c;
    team_.barrier();
    sum_a = sum_b = sum_c = 0.0;
    for (int m = 0; m < team_.size(); ++m) {
      sum_a += partial_[3 * m];
      sum_b += partial_[3 * m + 1];
      sum_c += partial_[3 * m + 2];
    }
    team_.barrier();  // everyone has read before anyone writes again
  }

  std::vector<double> normal_[3], spring_vector_[3];
  std::vector<double> alpha_, beta_;
  std::vector<double> rhs_[3], dv_[3], residual_[3], direction_[3], product_[3], preconditioned_[3],
      inverse_diagonal_[3];
  std::vector<double> partial_;
};

FastImplicitStepper::FastImplicitStepper(const MassSpringModel& model,
                                         const FastImplicitOptions& options)
    : impl_(std::make_unique<Implementation>(model, options)) {}
FastImplicitStepper::~FastImplicitStepper() = default;

void FastImplicitStepper::update_parameters(const MassSpringModel& model) {
  impl_->soa_.load_parameters(model);
  impl_->model_ = &model;
}
void FastImplicitStepper::set_state(const State& state) {
  impl_->soa_.set_state(*impl_->model_, state);
  impl_->time_ = state.time;
}
State FastImplicitStepper::state() const {
  return impl_->soa_.state(impl_->time_);
}
void FastImplicitStepper::step(double dt) {
  impl_->step(dt);
}
int FastImplicitStepper::last_cg_iterations() const {
  return impl_->last_iterations_;
}
int FastImplicitStepper::num_nodes() const {
  return impl_->soa_.num_nodes;
}
int FastImplicitStepper::num_springs() const {
  return impl_->soa_.num_springs;
}

}  // namespace msfem::massspring
