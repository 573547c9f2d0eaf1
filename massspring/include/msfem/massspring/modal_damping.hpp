#pragma once
// Spring dampers chosen for a modal damping ratio: what a simulator tunes so that the tissue
// settles after a press as fast as the real one does.

#include <Eigen/Core>

#include "msfem/massspring/mechanical_system.hpp"
#include "msfem/massspring/spring_network.hpp"

namespace msfem::massspring {

/// Each spring's axial damper d = 2 r sqrt(k m_a m_b / (m_a + m_b)): r of critical damping for the
/// two-body oscillator the spring forms with its end masses.
Eigen::VectorXd damping_for_ratio(const SpringNetwork& network, double ratio);

/// The damping ratio of the case's per-spring damping (msfem's case key `mass spring/damping
/// ratio`) that gives a mode of the loaded model the modal damping ratio `target` (springs damp
/// along their axis with d = 2 r sqrt(k m_a m_b/(m_a+m_b)), so the modal ratio is linear in r). The
/// mode is `shape` (a full-dof vector, e.g. the tool's static deflection: the motion that settles
/// after a press) taken as a Rayleigh quotient, or, when `shape` is empty, the slowest mode by
/// inverse iteration.
struct DampingFit {
  double frequency_hz = 0.0;            ///< of the mode
  double modal_ratio_per_unit_r = 0.0;  ///< the mode's ratio with r = 1
  double case_damping_ratio = 0.0;      ///< r that gives `target` (0 when not reachable)
  double target = 0.0;
  /// False when spring dampers barely act on the slowest mode (it moves across the springs), so no
  /// r reaches the target; the report says so.
  bool reachable = true;
};
DampingFit fit_damping(const MechanicalSystem& model, const Eigen::VectorXd& x, double target,
                       const Eigen::VectorXd& shape = Eigen::VectorXd());

}  // namespace msfem::massspring
