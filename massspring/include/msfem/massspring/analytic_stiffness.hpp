#pragma once

#include <Eigen/Core>

namespace msfem::massspring {

/// Starting spring stiffness from the material and the geometry, so that an uncalibrated model is
/// already of the right order. None of these is exact in general (hence calibration).

/// Lloyd, Székely & Harders 2007 (IEEE TVCG 13(5)), tetrahedral meshes: each tetrahedron
/// contributes k = 2√2/25 · E · l to each of its six edges (l = that edge's rest length); an edge
/// shared by several tetrahedra sums their contributions. Derived for a regular tetrahedron at ν =
/// 1/4.
double lloyd_tet_edge_stiffness(double youngs_modulus, double edge_length);

/// Van Gelder 1998 (J. Graphics Tools 3(2)), 3-D form: k = E · Σ V_t / l², the sum over the
/// tetrahedra that share the edge.
double van_gelder_stiffness(double youngs_modulus, double summed_tet_volume, double edge_length);

/// For networks without tetrahedra (surface tiers, skeleton): the springs of a region of volume V
/// are given k_s = 6 E V / (N l_s²), so that Σ k_s l_s² = 6 E V. This is the modulus of an
/// isotropic random spring network: C_ijkl = (1/V) Σ k l² n_i n_j n_k n_l, whose orientation
/// average gives C_1111 = Σ k l² / (5V) and, with the network's Cauchy ν = 1/4, E = (5/6) C_1111.
Eigen::VectorXd isotropic_network_stiffness(double youngs_modulus, double region_volume,
                                            const Eigen::VectorXd& rest_lengths);

/// The same rule with spring s's share of V in proportion to shares_s (> 0): k_s =
/// 6 E V shares_s / (Σ shares · l_s²). Equal shares give the form above; shares that follow the
/// local node spacing keep the modulus of a locally refined network what it is elsewhere (with
/// equal shares, a region with four times the springs per volume would be four times as stiff).
/// Throws ModelError for a share that is not finite and > 0, or sizes that differ.
Eigen::VectorXd isotropic_network_stiffness(double youngs_modulus, double region_volume,
                                            const Eigen::VectorXd& rest_lengths,
                                            const Eigen::VectorXd& shares);

}  // namespace msfem::massspring
