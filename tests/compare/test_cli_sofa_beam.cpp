// A network in SOFA's layout (tests/compare/sofa_beam.hpp) brought to msfem as a simulator would
// bring it: its static sag under gravity equals this file's own Newton solve of the same springs,
// the .vtu and the .xs3 give the same numbers, the FEM runs on the network's own surface, and a
// two-group calibration is handed back as the user's file and runs again to the same numbers.
#include <gtest/gtest.h>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>

#include "cli_runner.hpp"
#include "msfem/cases/network_file.hpp"
#include "msfem/compare/writers/fields_h5.hpp"
#include "sofa_beam.hpp"

namespace msfem {
namespace {

using testing::read_text;
using testing::run_msfem;
using testing::SofaBeam;
using testing::TemporaryDirectory;

const Eigen::Vector3d gravity(0, 0, -9.81);

// Static equilibrium of the beam's springs under gravity, its fixed end held: Newton on the
// spring forces k (l - l0) n with the exact tangent, from rest, to a residual of 1e-13 of the
// weight. Node-major displacements.
Eigen::VectorXd newton_sag(const SofaBeam& b) {
  const Eigen::Index n = b.points.rows();
  Eigen::VectorXd x(3 * n);
  for (Eigen::Index p = 0; p < n; ++p)
    x.segment<3>(3 * p) = b.points.row(p).transpose();
  const Eigen::VectorXd rest = x;
  const double weight = b.node_mass() * gravity.norm() * double(n);
  for (int iteration = 0; iteration < 50; ++iteration) {
    Eigen::VectorXd residual = Eigen::VectorXd::Zero(3 * n);
    std::vector<Eigen::Triplet<double>> t;
    for (Eigen::Index p = 0; p < n; ++p)
      residual.segment<3>(3 * p) += b.node_mass() * gravity;
    for (std::size_t s = 0; s < b.springs.size(); ++s) {
      const int i = b.springs[s][0], j = b.springs[s][1];
      const double l0 = (b.points.row(i) - b.points.row(j)).norm();
      const Eigen::Vector3d d = x.segment<3>(3 * j) - x.segment<3>(3 * i);
      const double l = d.norm(), k = b.spring_stiffness(s);
      const Eigen::Vector3d u = d / l;
      residual.segment<3>(3 * i) += k * (l - l0) * u;
      residual.segment<3>(3 * j) -= k * (l - l0) * u;
      // The stiffness of the spring (minus the residual's derivative).
      const Eigen::Matrix3d ke =
          k * ((1 - l0 / l) * Eigen::Matrix3d::Identity() + (l0 / l) * u * u.transpose());
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
          t.emplace_back(3 * i + r, 3 * i + c, ke(r, c));
          t.emplace_back(3 * j + r, 3 * j + c, ke(r, c));
          t.emplace_back(3 * i + r, 3 * j + c, -ke(r, c));
          t.emplace_back(3 * j + r, 3 * i + c, -ke(r, c));
        }
    }
    // Fixed nodes: an identity row and no residual.
    std::vector<Eigen::Triplet<double>> kept;
    for (const auto& e : t)
      if (!b.fixed[std::size_t(e.row() / 3)] && !b.fixed[std::size_t(e.col() / 3)])
        kept.push_back(e);
    for (Eigen::Index p = 0; p < n; ++p)
      if (b.fixed[std::size_t(p)]) {
        residual.segment<3>(3 * p).setZero();
        for (int r = 0; r < 3; ++r)
          kept.emplace_back(3 * p + r, 3 * p + r, 1.0);
      }
    if (residual.norm() < 1e-13 * weight) break;
    Eigen::SparseMatrix<double> k(3 * n, 3 * n);
    k.setFromTriplets(kept.begin(), kept.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(k);
    EXPECT_EQ(solver.info(), Eigen::Success);
    x += solver.solve(residual);
  }
  return x - rest;
}

// The surface vertices of `network:` geometry are the triangles' points in increasing id.
std::vector<int> surface_points(const SofaBeam& b) {
  std::set<int> ids;
  for (const auto& t : b.triangles)
    ids.insert(t.begin(), t.end());
  return {ids.begin(), ids.end()};
}

class SofaBeamNetwork : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TemporaryDirectory;
    beam_ = new SofaBeam(testing::make_sofa_beam({}));
    testing::write_sofa_beam_vtu(*beam_, path("beam.vtu"));
    testing::write_sofa_beam_xsp(*beam_, path("beam.xs3"));
    testing::write_sofa_beam_case(path("beam.prm"), "beam.vtu", "vtu=beam.vtu; xsp=beam.xs3");
  }
  static void TearDownTestSuite() {
    delete beam_;
    delete dir_;
  }
  static std::filesystem::path path(const std::string& name) { return *dir_ / name; }
  static inline TemporaryDirectory* dir_ = nullptr;
  static inline SofaBeam* beam_ = nullptr;
};

TEST_F(SofaBeamNetwork, SagsAsAnIndependentNewtonSolveInBothFormatsBesideTheFem) {
  const auto r = run_msfem("run " + path("beam.prm").string() + " --quiet --no-timing --out " +
                           path("run").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto h5 = path("run") / "fields.h5";
  const Eigen::MatrixXd vtu = compare::read_h5_matrix(h5, "/variants/vtu/displacement");
  const Eigen::MatrixXd xsp = compare::read_h5_matrix(h5, "/variants/xsp/displacement");
  const Eigen::VectorXd u = newton_sag(*beam_);
  const std::vector<int> surface = surface_points(*beam_);
  ASSERT_EQ(vtu.rows(), Eigen::Index(surface.size()));
  Eigen::MatrixXd expected(vtu.rows(), 3);
  for (std::size_t v = 0; v < surface.size(); ++v)
    expected.row(Eigen::Index(v)) = u.segment<3>(3 * surface[v]).transpose();
  EXPECT_LT((vtu - expected).norm(), 1e-8 * expected.norm());
  EXPECT_LT((xsp - vtu).norm(), 1e-12 * vtu.norm());
  // Gravity bends it a few percent of its length: a real sag, not round-off.
  const double length = (beam_->nx - 1) * beam_->spacing;
  const double tip = -expected.col(2).minCoeff();
  EXPECT_GT(tip, 0.01 * length);
  EXPECT_LT(tip, 0.1 * length);
  const auto s = nlohmann::json::parse(read_text(path("run") / "summary.json"));
  ASSERT_EQ(s["variants"].size(), 2u);
  for (const char* metric : {"rel_l2_error", "max_error_m"})
    EXPECT_NEAR(s["variants"][0][metric].get<double>(), s["variants"][1][metric].get<double>(),
                1e-10 * s["variants"][0][metric].get<double>())
        << metric;
  EXPECT_EQ(s["variants"][0]["springs"], 24519);
}

double mean_test_error(const nlohmann::json& side) {
  double sum = 0;
  for (const auto& load : side["test"])
    sum += load["rel_l2_error"].get<double>();
  return sum / side["test"].size();
}

// Grid edges and diagonals fitted on two tool presses with gravity (the top and a side, at the
// middle of the beam), checked on two others (the bottom, the other side).
const std::string tool = " --set loads/tool/mode=prescribed --set loads/tool/radius=0.015";
const std::string loads =
    " --train '0,0,1@0.004; 0,1,0@0.003' --test '0,0,-1@0.002; 0,-1,0@0.0025'";

TEST_F(SofaBeamNetwork, TwoGroupsCalibratedAreHandedBackAndRunAgainToTheSameNumbers) {
  const auto r = run_msfem("calibrate " + path("beam.prm").string() + tool + " --variant vtu" +
                           loads + " --quiet --no-compare --out " + path("cal").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto c = nlohmann::json::parse(read_text(path("cal") / "calibration.json"));
  EXPECT_LT(mean_test_error(c["after"]), 0.8 * mean_test_error(c["before"]));
  ASSERT_EQ(c["calibrated_network"], "calibrated_vtu.vtu");

  // The user's file with the two groups' stiffness scaled, all else as it was.
  const cases::NetworkFile original = cases::read_network(path("beam.vtu"));
  const cases::NetworkFile back = cases::read_network(path("cal") / "calibrated_vtu.vtu");
  std::map<std::string, double> factor;
  for (const auto& g : c["coefficients"])
    factor[g["group"]] = g["factor"].get<double>();
  ASSERT_EQ(factor.size(), 2u);
  EXPECT_EQ(back.points, original.points);
  EXPECT_EQ(back.springs, original.springs);
  EXPECT_EQ(back.triangles, original.triangles);
  EXPECT_EQ(*back.mass, *original.mass);
  EXPECT_EQ(*back.fixed, *original.fixed);
  EXPECT_EQ(back.spring_group, original.spring_group);
  for (Eigen::Index s = 0; s < original.stiffness.size(); ++s) {
    const double f = factor.at(original.group_names[std::size_t(original.spring_group[s])]);
    ASSERT_NEAR(back.stiffness[s], f * original.stiffness[s], 1e-9 * back.stiffness[s]) << s;
  }

  // calibrated.prm runs the handed-back file: its numbers before any fit are the fit's.
  const auto again =
      run_msfem("calibrate " + (path("cal") / "calibrated.prm").string() + tool + loads +
                " --max-evaluations 3 --quiet --no-compare --out " + path("again").string());
  ASSERT_EQ(again.exit_code, 0) << again.err;
  const auto d = nlohmann::json::parse(read_text(path("again") / "calibration.json"));
  EXPECT_EQ(d["variant"], "vtu");
  EXPECT_EQ(d["fem"]["solves"], 0);  // the same FEM, from the cache
  for (const char* set : {"train", "test"})
    for (std::size_t i = 0; i < c["after"][set].size(); ++i)
      for (const char* metric : {"rel_l2_error", "reaction_force_rel_error"}) {
        const double fitted = c["after"][set][i][metric], reloaded = d["before"][set][i][metric];
        EXPECT_NEAR(reloaded, fitted, 1e-10 * fitted) << set << " " << i << " " << metric;
      }
}

// An Xsp network has one group, and comes back as .xs3 with its records' ks scaled.
TEST_F(SofaBeamNetwork, AnXspNetworkComesBackAsXsp) {
  const auto r = run_msfem("calibrate " + path("beam.prm").string() + tool +
                           " --variant xsp --train '0,0,1@0.004' --test '0,1,0@0.003' "
                           "--max-evaluations 8 --quiet --no-compare --out " +
                           path("cal_xsp").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto c = nlohmann::json::parse(read_text(path("cal_xsp") / "calibration.json"));
  ASSERT_EQ(c["calibrated_network"], "calibrated_xsp.xs3");
  const double f = c["coefficients"][0]["factor"];
  const cases::NetworkFile original = cases::read_network(path("beam.xs3"));
  const cases::NetworkFile back = cases::read_network(path("cal_xsp") / "calibrated_xsp.xs3");
  EXPECT_EQ(back.points, original.points);
  EXPECT_EQ(*back.mass, *original.mass);
  EXPECT_LT((back.stiffness - f * original.stiffness).norm(), 1e-12 * back.stiffness.norm());
  EXPECT_NE(f, 1.0);
}

}  // namespace
}  // namespace msfem
