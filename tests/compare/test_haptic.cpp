// msfem haptic: the tool path read and made, the values a replay may change, and a replay as a
// user runs it: the force it renders is the model's own equilibrium force once the tool rests, a
// --set-at change shows in the trace at its time and not before, and the FEM it measures against
// is the FEM msfem run solves at the same tool.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_runner.hpp"
#include "msfem/cases/errors.hpp"
#include "msfem/compare/pipeline/haptic.hpp"

namespace msfem {
namespace {

using testing::read_text;
using testing::run_msfem;
using testing::TemporaryDirectory;

const std::string case_file = std::string(MSFEM_CASES_DIR) + "/sphere_indent.prm";
// Implicit Euler: under symplectic Euler three_tier's contact never settles on this sphere (msfem
// run reports settled = false; the replay shows it bouncing at 5 Hz), and a held tool's force
// must be steady for a change to show.
const std::vector<std::string> small = {"fem/degree=1", "fem/error estimate=none",
                                        "mass spring/variants=three_tier",
                                        "timing/integrator=implicit_euler"};

std::string small_options() {
  std::string s;
  for (const auto& set : small)
    s += " --set '" + set + "'";
  return s;
}

std::filesystem::path write(const std::filesystem::path& file, const std::string& text) {
  std::ofstream(file) << text;
  return file;
}

// A device path for the small case's tool: from 6 mm above the surface, pressed `depth` deep along
// the tool's normal at 0.3 s, then held; written to `dir`/press.csv. Returns the file and the
// tool's outward normal.
std::pair<std::filesystem::path, Eigen::Vector3d> press_and_hold(const std::filesystem::path& dir,
                                                                 double depth) {
  const compare::Problem problem = compare::make_problem(cases::read_case(case_file, small));
  const compare::ToolPlacement& tool = problem.tools.front();
  const Eigen::Vector3d n = tool.outward_normal, above = tool.contact_point + 0.006 * n;
  const Eigen::Vector3d pressed = tool.contact_point + (tool.radius - depth) * n;
  std::ostringstream csv;
  csv.precision(17);
  csv << "t_s,x_m,y_m,z_m\n0," << above.x() << ',' << above.y() << ',' << above.z() << '\n';
  for (double t : {0.3, 3.0})
    csv << t << ',' << pressed.x() << ',' << pressed.y() << ',' << pressed.z() << '\n';
  return {write(dir / "press.csv", csv.str()), n};
}

TEST(ToolPath, IsLinearBetweenSamplesAndHeldOutside) {
  const compare::ToolPath path({1.0, 2.0, 4.0}, {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0),
                                                 Eigen::Vector3d(1, 2, 0)});
  EXPECT_TRUE(path.at(0.0).isApprox(Eigen::Vector3d(0, 0, 0)));
  EXPECT_TRUE(path.at(1.25).isApprox(Eigen::Vector3d(0.25, 0, 0)));
  EXPECT_TRUE(path.at(3.0).isApprox(Eigen::Vector3d(1, 1, 0)));
  EXPECT_TRUE(path.at(9.0).isApprox(Eigen::Vector3d(1, 2, 0)));
  EXPECT_THROW(compare::ToolPath({0.0, 0.0}, {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}),
               std::invalid_argument);
}

TEST(ToolPath, ReadsADeviceLogAndWritesItBackExactly) {
  TemporaryDirectory dir;
  const auto file = write(dir / "log.csv",
                          "# a PHANTOM log\n"
                          "t_s,x_m,y_m,z_m,qw,qx,qy,qz\n"
                          "0.0, 0.1, 0.2, 0.3, 1, 0, 0, 0\n"
                          "0.001,0.1000000001,0.2,0.3,0.7071067811865476,0,0.7071067811865476,0\n");
  const compare::ToolPath path = compare::read_tool_path(file);
  EXPECT_TRUE(path.had_orientation());
  // A spreadsheet's UTF-8 byte order mark before the header is not a column.
  const auto bom = write(dir / "bom.csv", "\xEF\xBB\xBFt_s,x_m,y_m,z_m\n0,0,0,0\n1,1,0,0\n");
  EXPECT_EQ(compare::read_tool_path(bom).times().size(), 2u);
  ASSERT_EQ(path.times().size(), 2u);
  EXPECT_EQ(path.centers()[1].x(), 0.1000000001);
  compare::write_tool_path(path, dir / "back.csv");
  const compare::ToolPath back = compare::read_tool_path(dir / "back.csv");
  EXPECT_EQ(back.times(), path.times());
  EXPECT_EQ(back.centers()[1], path.centers()[1]);
  EXPECT_FALSE(back.had_orientation());
}

TEST(ToolPath, RefusesABadLogNamingTheLine) {
  TemporaryDirectory dir;
  const auto refused = [&](const std::string& text, const std::string& expected) {
    const auto file = write(dir / "bad.csv", text);
    try {
      compare::read_tool_path(file);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const cases::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refused("0,0,0,0\n1,0,0\n", "bad.csv:2: 3 columns");
  refused("0,0,0,0\n1,0,x,0\n", "bad.csv:2: column 3 'x' is not a finite number");
  refused("0,0,0,0\n0,0,0,1\n", "bad.csv:2: time 0 s does not come after");
  refused("0,0,0,0,1,0,0,0\n1,0,0,0,2,0,0,0\n", "bad.csv:2: the orientation quaternion has norm 2");
  refused("0,0,0,0\n1,0,0,0,1,0,0,0\n", "bad.csv:2: 8 columns where the rows above have 4");
  refused("t_s,x_m,y_m,z_m\n0,0,0,nan\n", "is not a finite number");
  refused("0,0,0,0\n", "needs two rows or more");
  refused("O.5,0,0,0\n1,0,0,0\n2,0,0,0\n", "bad.csv:1: column 1 'O.5' is not a finite number");
}

class HapticPath : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    problem_ = new compare::Problem(compare::make_problem(cases::read_case(case_file, small)));
  }
  static const compare::Problem& problem() { return *problem_; }
  static compare::Problem* problem_;
};
compare::Problem* HapticPath::problem_ = nullptr;

// The default path presses the case's tool to the case's depth and keeps that depth along the
// slide (the faceted sphere's normals are interpolated, so within a tenth of it), sliding 10 mm.
TEST_F(HapticPath, DefaultPathPressesToTheCaseDepthAndSlidesTenMillimetres) {
  const compare::ToolPath path = compare::default_tool_path(problem());
  const compare::ToolPlacement& tool = problem().tools.front();
  const double r = tool.radius, d = tool.depth;
  EXPECT_NEAR(compare::placement_at(problem(), path.at(0.0), r).depth, -0.005, 1e-9);
  EXPECT_NEAR(compare::placement_at(problem(), path.at(0.5), r).depth, 0.0, 1e-9);
  EXPECT_NEAR(compare::placement_at(problem(), path.at(1.5), r).depth, d, 1e-12);
  for (double t = 2.0; t <= 4.0; t += 0.1)
    EXPECT_NEAR(compare::placement_at(problem(), path.at(t), r).depth, d, 0.1 * d) << t;
  // The centre travels on a sphere of radius R + r - d: 10 mm along the surface is that much
  // longer an arc.
  const double R = 0.05, arc = (path.at(4.0) - path.at(2.0)).norm();
  EXPECT_NEAR(arc, 0.010 * (R + r - d) / R, 3e-4);
  EXPECT_NEAR(compare::placement_at(problem(), path.at(6.0), r).depth, -0.005, 5e-4);
}

TEST_F(HapticPath, SamplesWhereTheToolTouchesAndRefusesAPathThatNeverDoes) {
  const compare::ToolPath path = compare::default_tool_path(problem());
  const auto samples = compare::path_samples(problem(), path, 6.0, 8, "default");
  ASSERT_EQ(samples.size(), 8u);
  for (const auto& s : samples) {
    EXPECT_GT(s.t_s, 0.5);
    EXPECT_LT(s.t_s, 5.5);
    EXPECT_GT(s.tool.depth, 0.0);
    EXPECT_TRUE(s.tool.frictionless);
    EXPECT_TRUE(s.tool.pushed_center().isApprox(path.at(s.t_s), 1e-12));
  }
  const compare::ToolPath away({0.0, 1.0},
                               {Eigen::Vector3d(0, 0, 0.2), Eigen::Vector3d(0.2, 0, 0)});
  EXPECT_THROW(compare::path_samples(problem(), away, 1.0, 8, "away.csv"), cases::InputError);
  // Touching for a moment at either end only: no time the FEM is compared at presses.
  const Eigen::Vector3d touch = path.at(1.5), off = path.at(0.0);
  const compare::ToolPath taps({0.0, 0.01, 0.02, 9.98, 9.99, 10.0},
                               {touch, off, off, off, off, touch});
  EXPECT_THROW(compare::path_samples(problem(), taps, 10.0, 8, "taps.csv"), cases::InputError);
}

TEST(HapticChanges, ParsesSortsAndRefusesWhatCannotChangeWhileRunning) {
  const auto changes = compare::parse_parameter_changes(
      {"2:mass spring/damping ratio=0.8", "1.5:mass spring/group scales=tier1_edges:2"}, case_file,
      small, 3.0);
  ASSERT_EQ(changes.size(), 2u);
  EXPECT_EQ(changes[0].t_s, 1.5);
  EXPECT_EQ(changes[0].after.mass_spring.group_scales.size(), 1u);
  EXPECT_EQ(changes[1].after.mass_spring.damping_ratio, 0.8);
  EXPECT_EQ(changes[1].after.mass_spring.group_scales.size(), 1u);  // the earlier one kept
  const auto refused = [&](const std::string& option, const std::string& expected) {
    try {
      compare::parse_parameter_changes({option}, case_file, small, 3.0);
      ADD_FAILURE() << "accepted: " << option;
    } catch (const cases::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refused("1:material/youngs modulus=5000", "cannot change while the model runs");
  refused("4:mass spring/damping ratio=0.8", "not a number of seconds in [0, 3");
  EXPECT_EQ(
      compare::parse_parameter_changes({"3:mass spring/damping ratio=0.8"}, case_file, small, 3.0)
          .size(),
      1u);  // the last tick itself
  refused("x:mass spring/damping ratio=0.8", "the time 'x'");
  refused("1:mass spring/group scales=no_such_group:2", "no_such_group");
  refused("1:material/density=-5", "density");
  refused("1 mass spring/damping ratio", "expected T:SECTION/KEY=VALUE");
}

// The replay as a user runs it: the tool pressed 4 mm in 0.3 s and held; at 1.5 s the surface
// springs are made three times stiffer, as from the seed's menu (the force rises about 11 %).
TEST(HapticReplay, RendersTheModelsForceAndShowsAChangeAtItsTime) {
  TemporaryDirectory dir;
  const double depth = 0.004;
  const auto press = press_and_hold(dir.path(), depth);
  const std::filesystem::path& path = press.first;
  const Eigen::Vector3d n = press.second;
  const auto out = dir / "haptic";
  const auto r = run_msfem("haptic " + case_file + small_options() + " --path " + path.string() +
                           " --seconds 2.5 --set-at '1.5:mass spring/group scales=tier1_edges:3'" +
                           " --quiet --json --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto json = nlohmann::json::parse(r.out);
  EXPECT_EQ(json, nlohmann::json::parse(read_text(out / "haptic.json")));
  ASSERT_EQ(json["variants"].size(), 1u);
  const auto& v = json["variants"][0];
  EXPECT_EQ(v["name"], "three_tier");
  EXPECT_EQ(v["precision"], "double");
  EXPECT_EQ(v["ticks"], 2501);
  EXPECT_LE(v["step_ms"]["p50"].get<double>(), v["step_ms"]["p99"].get<double>());
  EXPECT_LE(v["step_ms"]["p99"].get<double>(), v["step_ms"]["max"].get<double>());
  for (const char* key : {"rate_hz", "deadline_misses", "step_ms", "model_rate_hz"})
    EXPECT_TRUE(json.contains(key) || v.contains(key)) << key;
  ASSERT_EQ(v["changes_applied"].size(), 1u);
  EXPECT_GE(v["changes_applied"][0]["t_s"].get<double>(), 1.5);

  // The trace: the normal force before the change, after it, and when it first moved.
  std::istringstream trace(read_text(out / "trace_three_tier.csv"));
  std::string line;
  std::getline(trace, line);
  std::vector<std::pair<double, double>> push;  // t, F·n
  while (std::getline(trace, line)) {
    double t, x, y, z, fx, fy, fz;
    char c;
    std::istringstream(line) >> t >> c >> x >> c >> y >> c >> z >> c >> fx >> c >> fy >> c >> fz;
    push.emplace_back(t, Eigen::Vector3d(fx, fy, fz).dot(n));
  }
  ASSERT_EQ(push.size(), 2501u);
  const auto mean_over = [&](double from, double to) {
    double sum = 0;
    int count = 0;
    for (const auto& [t, f] : push)
      if (t >= from && t < to) sum += f, ++count;
    return sum / count;
  };
  const double before = mean_over(1.0, 1.5), after = mean_over(2.0, 2.5);
  ASSERT_GT(before, 0.0);
  EXPECT_GT(after, 1.05 * before) << "stiffer springs push the held tool harder";
  double first_moved = 1e9;
  for (const auto& [t, f] : push)
    if (t >= 1.0 && std::abs(f - before) > 0.02 * before) {
      first_moved = t;
      break;
    }
  EXPECT_GE(first_moved, 1.5) << "the force moved before the change";
  EXPECT_LT(first_moved, 1.7) << "the change took too long to show";

  // Held still, the rendered force is the variant's own equilibrium there; the FEM it is measured
  // against is the FEM msfem run solves for the same tool.
  const auto run_out = dir / "run";
  ASSERT_EQ(run_msfem("run " + case_file + small_options() +
                      " --set loads/tool/depth=" + std::to_string(depth) +
                      " --quiet --no-timing --no-curve --out " + run_out.string())
                .exit_code,
            0);
  const auto summary = nlohmann::json::parse(read_text(run_out / "summary.json"));
  const Eigen::Vector3d run_fem(summary["fem"]["reaction_force_N"][0].get<double>(),
                                summary["fem"]["reaction_force_N"][1].get<double>(),
                                summary["fem"]["reaction_force_N"][2].get<double>());
  const double run_variant = summary["variants"][0]["reaction_force_N"][2].get<double>();
  int held = 0;
  for (const auto& s : v["force_error_along_path"]["samples"]) {
    if (s["t_s"].get<double>() < 0.35) continue;
    ++held;
    const Eigen::Vector3d fem(s["fem_force_n"][0].get<double>(), s["fem_force_n"][1].get<double>(),
                              s["fem_force_n"][2].get<double>());
    EXPECT_LT((fem - run_fem).norm(), 0.02 * run_fem.norm()) << s.dump();
    if (s["t_s"].get<double>() < 1.5) {
      EXPECT_NEAR(s["static_force_n"][2].get<double>(), run_variant, 1e-3 * std::abs(run_variant));
      EXPECT_NEAR(s["force_n"][2].get<double>(), run_variant, 0.05 * std::abs(run_variant));
    }
  }
  EXPECT_GE(held, 4);
}

// timing/precision = float: the model thread steps in float, and with the tool pressed 4 mm and
// held the force it renders is the variant's static force there (the double solve's) as closely
// as the double model's is in RendersTheModelsForceAndShowsAChangeAtItsTime.
TEST(HapticReplay, AFloatModelRendersTheHeldForce) {
  TemporaryDirectory dir;
  const auto path = press_and_hold(dir.path(), 0.004).first;
  const auto out = dir / "haptic";
  const auto r =
      run_msfem("haptic " + case_file + small_options() + " --set timing/precision=float --path " +
                path.string() + " --seconds 1 --quiet --json --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto json = nlohmann::json::parse(r.out);
  ASSERT_EQ(json["variants"].size(), 1u);
  const auto& v = json["variants"][0];
  EXPECT_EQ(v["precision"], "float");
  EXPECT_EQ(v["stepper"], "fast_implicit");
  int held = 0;
  for (const auto& s : v["force_error_along_path"]["samples"]) {
    if (s["t_s"].get<double>() < 0.35) continue;
    ++held;
    const double static_force = s["static_force_n"][2].get<double>();
    EXPECT_NEAR(s["force_n"][2].get<double>(), static_force, 0.05 * std::abs(static_force))
        << s.dump();
  }
  EXPECT_GE(held, 4);
}

TEST(HapticCommand, RefusesBadOptionsBeforeAnySolve) {
  TemporaryDirectory dir;
  const auto refused = [&](const std::string& args, const std::string& expected) {
    const auto r = run_msfem("haptic " + case_file + small_options() + " " + args + " --out " +
                             (dir / "never").string());
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "never"));
  };
  refused("--rate 0", "--rate '0'");
  refused("--seconds -1", "--seconds '-1'");
  refused("--path " + (dir / "missing.csv").string(), "missing.csv: cannot open the tool path");
  refused("--set-at '1:fem/degree=2'", "cannot change while the model runs");
  refused("--rate 1e3x", "--rate '1e3x'");
  refused("--rate 10", "at least 50 Hz");
  refused("--seconds 0.0001", "shorter than one tick");
  refused("--rate 100000 --seconds 3600", "at most 10000000");
  refused("--seconds 2 --set-at '2.5:mass spring/damping ratio=0.8'", "the replay's last tick");
}

}  // namespace
}  // namespace msfem
