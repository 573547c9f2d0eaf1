// Every value of every enumerated case setting: the case language accepts it, reads it back as the
// value its name table says, refuses any other name when the file is read (file and line), and the
// code that consumes the setting does what the value asks.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "msfem/cases/errors.hpp"
#include "msfem/cases/setting_names.hpp"
#include "msfem/cases/surface_generators.hpp"
#include "msfem/cases/surface_io.hpp"
#include "msfem/compare/pipeline/case_run.hpp"
#include "msfem/compare/pipeline/fem_error_estimate.hpp"
#include "msfem/compare/pipeline/fem_run.hpp"

namespace msfem::compare {
namespace {

using cases::CaseParameters;
using cases::name_of;
using testing::TemporaryDirectory;

const std::string small_case = std::string(MSFEM_TEST_DATA_DIR) + "/small_sphere.prm";

CaseParameters with(std::vector<std::string> overrides, const std::string& file = small_case) {
  return cases::read_case(file, overrides);
}

// "a/b/key" as the nested subsections of a case file that set key to `value`.
std::string case_text(const std::string& path, const std::string& value) {
  std::string text, indent;
  std::size_t begin = 0;
  for (std::size_t slash; (slash = path.find('/', begin)) != std::string::npos; begin = slash + 1) {
    text += indent + "subsection " + path.substr(begin, slash - begin) + "\n";
    indent += "  ";
  }
  text += indent + "set " + path.substr(begin) + " = " + value + "\n";
  while (!indent.empty()) {
    indent.resize(indent.size() - 2);
    text += indent + "end\n";
  }
  return text;
}

// Every name of Enum's table, set at `key`, is read back as its value; a name not in the table is
// refused when the file is read, with the file and the line of the `set`.
template <typename Enum, typename Get>
void expect_language_takes_exactly_the_table(
    const std::string& key, Get get, const std::vector<std::string>& also = {},
    const std::map<std::string, std::string>& also_with_value = {}) {
  for (const auto& entry : cases::names_of(Enum{}).entries) {
    std::vector<std::string> overrides = also;
    if (const auto it = also_with_value.find(entry.name); it != also_with_value.end())
      overrides.push_back(it->second);
    overrides.push_back(key + "=" + entry.name);
    EXPECT_EQ(get(with(overrides)), entry.value) << key << " = " << entry.name;
  }
  TemporaryDirectory dir;
  const auto file = dir / "bad.prm";
  std::ofstream(file) << case_text(key, "no_such_value");
  try {
    cases::read_case(file);
    ADD_FAILURE() << key << ": an unknown value was accepted";
  } catch (const cases::InputError& e) {
    const std::string message = e.what();
    const int depth = static_cast<int>(std::count(key.begin(), key.end(), '/'));
    EXPECT_NE(message.find("bad.prm:" + std::to_string(depth + 1)), std::string::npos) << message;
    EXPECT_NE(message.find("no_such_value"), std::string::npos) << message;
  }
}

TEST(CaseSettings, EveryEnumeratedKeyTakesExactlyItsTable) {
  using cases::FemParameters;
  using cases::SupportParameters;
  using cases::ToolParameters;
  // (A unit applies to a surface file only; a generated surface is refused one.)
  expect_language_takes_exactly_the_table<cases::LengthUnit>(
      "geometry/unit", [](const CaseParameters& p) { return p.geometry.unit; },
      {"geometry/source=" + std::string(MSFEM_CASES_DIR) + "/data/pancreas_vh_female_m.obj"});
  expect_language_takes_exactly_the_table<SupportParameters::Kind>(
      "support/fixed region", [](const CaseParameters& p) { return p.support.kind; },
      {"support/sphere radius=0.01"});
  expect_language_takes_exactly_the_table<ToolParameters::Mode>(
      "loads/tool/mode", [](const CaseParameters& p) { return p.loads.tool.mode; });
  expect_language_takes_exactly_the_table<cases::Variant>(
      "mass spring/variants", [](const CaseParameters& p) { return p.mass_spring.variants.at(0); });
  expect_language_takes_exactly_the_table<massspring::TetStiffnessRule>(
      "mass spring/stiffness model",
      [](const CaseParameters& p) { return p.mass_spring.stiffness_model; });
  expect_language_takes_exactly_the_table<massspring::InnerTierMethod>(
      "mass spring/three tier/inner tiers",
      [](const CaseParameters& p) { return p.mass_spring.inner_tiers; });
  expect_language_takes_exactly_the_table<cases::FemSolver>(
      "fem/solver", [](const CaseParameters& p) { return p.fem.solver; });
  expect_language_takes_exactly_the_table<FemParameters::ErrorEstimate>(
      "fem/error estimate", [](const CaseParameters& p) { return p.fem.error_estimate; }, {},
      {{"lower_degree", "fem/degree=2"}});
  expect_language_takes_exactly_the_table<massspring::IntegratorKind>(
      "timing/integrator", [](const CaseParameters& p) { return p.timing.integrator; });
  expect_language_takes_exactly_the_table<cases::CalibrationModel>(
      "calibration/model", [](const CaseParameters& p) { return p.calibration.model; });
  EXPECT_FALSE(with({}).calibration.variant.has_value());  // empty: the first of the variants
}

// calibration/variant names a built-in variant or one of the case's networks; anything else is
// refused naming the key and the value.
TEST(CaseSettings, TheCalibratedVariantIsABuiltInOneOrANetworkOfTheCase) {
  for (const auto& entry : cases::names_of(cases::Variant{}).entries)
    EXPECT_EQ(with({std::string("calibration/variant=") + entry.name}).calibration.variant,
              std::string(entry.name));
  TemporaryDirectory dir;
  std::ofstream(dir / "mine.vtu") << "";  // read when a run builds it, not with the case
  EXPECT_EQ(
      with({"mass spring/networks=mine=" + (dir / "mine.vtu").string(), "calibration/variant=mine"})
          .calibration.variant,
      "mine");
  try {
    with({"calibration/variant=no_such_value"});
    ADD_FAILURE() << "an unknown variant was accepted";
  } catch (const cases::InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("calibration/variant: unknown value 'no_such_value'"), std::string::npos)
        << message;
  }
}

// The length unit scales a surface file's coordinates into metres.
TEST(CaseSettings, TheLengthUnitScalesTheFile) {
  TemporaryDirectory dir;
  cases::write_surface(dir / "ball.obj", cases::generate_surface("icosphere:2:50"));
  const std::string source = "geometry/source=" + (dir / "ball.obj").string();
  // Deep enough to be more than round-off on the 100 m ball, shallow enough for the 10 cm one.
  const std::vector<std::string> tool = {"loads/tool/depth=0.02",
                                         "loads/tool/curve depths=0.01,0.02"};
  for (const cases::LengthUnit unit : cases::all_values<cases::LengthUnit>()) {
    std::vector<std::string> overrides = tool;
    overrides.push_back(source);
    overrides.push_back("geometry/unit=" + name_of(unit));
    const Problem problem = make_problem(with(overrides));
    const double radius = problem.surface.vertices.rowwise().norm().maxCoeff();
    EXPECT_NEAR(radius, 50 * cases::metres_per(unit), 1e-9 * radius) << name_of(unit);
  }
}

// Each fixed region fixes what its geometry says: the centre and not the surface for the inner
// core and a small sphere, the lower half and not the upper for the half space z <= 0.
TEST(CaseSettings, EachFixedRegionHoldsItsOwnNodes) {
  const Eigen::Vector3d centre(0, 0, 0), low(0, 0, -0.045), high(0, 0, 0.045);
  for (const auto kind : cases::all_values<cases::SupportParameters::Kind>()) {
    const Problem p =
        make_problem(with({"support/fixed region=" + name_of(kind), "support/sphere radius=0.01"}));
    const bool half_space = kind == cases::SupportParameters::Kind::half_space;
    EXPECT_TRUE(p.fixed_region(half_space ? low : centre)) << name_of(kind);
    EXPECT_FALSE(p.fixed_region(high)) << name_of(kind);
    EXPECT_EQ(p.fixed_region(low), half_space) << name_of(kind);
  }
}

// Bonded holds a patch of nodes on the sphere; contact holds none and presses by a contact field.
TEST(CaseSettings, EachToolModeReachesTheSpringModel) {
  for (const auto mode : cases::all_values<cases::ToolParameters::Mode>()) {
    const Problem problem = make_problem(with({"loads/tool/mode=" + name_of(mode)}));
    const bool contact = mode == cases::ToolParameters::Mode::contact;
    EXPECT_EQ(problem.tools.front().frictionless, contact);
    const BuiltVariant v =
        build_variant(cases::Variant::single_layer, problem, {}, problem.tools.front());
    EXPECT_EQ(v.tool_patch.empty(), contact) << name_of(mode);
    EXPECT_EQ(v.model->contact() != nullptr, contact) << name_of(mode);
  }
}

// Each variant builds its own network (its groups), and the stiffness rule and the inner-tier
// method change what tet_edges and three_tier build.
TEST(CaseSettings, VariantStiffnessModelAndInnerTiersChangeTheNetwork) {
  const Problem problem = make_problem(with({"geometry/source=ellipsoid:2:0.05:0.04:0.03"}));
  const auto mesh = mesh_problem(problem);
  for (const cases::Variant kind : cases::all_values<cases::Variant>()) {
    const BuiltVariant v = build_variant(kind, problem, mesh, std::nullopt);
    EXPECT_EQ(v.name, name_of(kind));
    EXPECT_EQ(v.model->network().spring_group_names, spring_groups_of(kind, problem.parameters))
        << v.name;
  }
  auto network_with = [&](const std::string& setting, cases::Variant kind) {
    Problem changed = problem;
    changed.parameters = with({"geometry/source=ellipsoid:2:0.05:0.04:0.03", setting});
    return build_variant(kind, changed, mesh, std::nullopt).model->network();
  };
  const auto lloyd = network_with("mass spring/stiffness model=lloyd", cases::Variant::tet_edges);
  const auto gelder =
      network_with("mass spring/stiffness model=van_gelder", cases::Variant::tet_edges);
  EXPECT_GT((lloyd.stiffness - gelder.stiffness).norm(), 1e-3 * lloyd.stiffness.norm());
  const auto scaled =
      network_with("mass spring/three tier/inner tiers=scaled", cases::Variant::three_tier);
  const auto offset =
      network_with("mass spring/three tier/inner tiers=offset", cases::Variant::three_tier);
  EXPECT_GT((scaled.rest_positions - offset.rest_positions).norm(), 1e-4);
  // On a convex ellipsoid the distance field's copies go along the normals, not toward the
  // centroid.
  const auto field =
      network_with("mass spring/three tier/inner tiers=distance_field", cases::Variant::three_tier);
  EXPECT_GT((scaled.rest_positions - field.rest_positions).norm(), 1e-4);
  EXPECT_GT((offset.rest_positions - field.rest_positions).norm(), 1e-6);
}

// The three linear solvers give the same reference, each naming itself.
TEST(CaseSettings, EverySolverSolvesTheSameReference) {
  std::optional<Eigen::MatrixX3d> first;
  for (const cases::FemSolver solver : cases::all_values<cases::FemSolver>()) {
    const Problem problem = make_problem(with({"fem/solver=" + name_of(solver)}));
    const auto mesh = mesh_problem(problem);
    const FemSolution s = solve_fem(problem, mesh, problem.tools.front());
    EXPECT_EQ(s.solver, name_of(solver));
    if (!first) first = s.surface_displacement;
    EXPECT_LT((s.surface_displacement - *first).norm(), 1e-6 * first->norm()) << s.solver;
  }
}

// Each method of the reference's error estimate is the one planned (auto: degree at degree 1).
TEST(CaseSettings, EveryErrorEstimateIsPlannedAsAsked) {
  using Method = cases::FemParameters::ErrorEstimate;
  for (const Method method : cases::all_values<Method>()) {
    // lower_degree estimates a P2 reference by P1; the others are asked of this case's P1.
    const std::string degree = method == Method::lower_degree ? "2" : "1";
    const Problem problem =
        make_problem(with({"fem/error estimate=" + name_of(method), "fem/degree=" + degree}));
    const auto mesh = mesh_problem(problem);
    const Method planned = plan_error_estimate(problem, mesh, 1, 1).method;
    EXPECT_EQ(planned, method == Method::automatic ? Method::degree : method) << name_of(method);
  }
}

// Every integrator is the one timed, the implicit one at the haptic step it is reported at.
TEST(CaseSettings, EveryIntegratorIsTheOneTimed) {
  const Problem problem =
      make_problem(with({"loads/tool/enabled=false", "loads/gravity=0,0,-9.81"}));
  const BuiltVariant v = build_variant(cases::Variant::single_layer, problem, {}, std::nullopt);
  for (const auto kind : cases::all_values<massspring::IntegratorKind>()) {
    cases::TimingParameters timing = with({"timing/integrator=" + name_of(kind)}).timing;
    timing.steps = 50;
    const Timing t = time_variant(v, timing, v.model->initial_state(), false);
    EXPECT_EQ(t.integrator, name_of(kind));
    EXPECT_GT(t.steps_per_second, 0.0);
    if (kind == massspring::IntegratorKind::implicit_euler) {
      EXPECT_EQ(t.stable_dt_s, 1e-3);
      EXPECT_EQ(t.dt_s, t.stable_dt_s);  // timed at the step its real-time factor is for
    } else {
      EXPECT_EQ(t.dt_s, 0.5 * t.stable_dt_s) << name_of(kind);
    }
    // On the code a simulator runs: the fast kernels, explicit or implicit.
    EXPECT_EQ(t.stepper, kind == massspring::IntegratorKind::implicit_euler ? "fast_implicit"
                                                                            : "fast_explicit")
        << name_of(kind);
  }
  // A force field (the contact tool) keeps every scheme on the fast kernels.
  const Problem pressed = make_problem(with({"loads/tool/mode=contact"}));
  const auto mesh = mesh_problem(pressed);
  const BuiltVariant contact =
      build_variant(cases::Variant::single_layer, pressed, mesh, pressed.tools.front());
  ASSERT_TRUE(contact.model->has_added_fields());
  for (const auto kind :
       {massspring::IntegratorKind::central_difference, massspring::IntegratorKind::rk4,
        massspring::IntegratorKind::implicit_euler}) {
    cases::TimingParameters timing = with({"timing/integrator=" + name_of(kind)}).timing;
    timing.steps = 50;
    const Timing t = time_variant(contact, timing, contact.model->initial_state(), false);
    EXPECT_EQ(t.stepper, kind == massspring::IntegratorKind::implicit_euler ? "fast_implicit"
                                                                            : "fast_explicit");
  }
}

// The calibration model and variant reach msfem calibrate.
TEST(CaseSettings, CalibrationModelAndVariantReachTheFit) {
  const std::string calibrate_case = std::string(MSFEM_TEST_DATA_DIR) + "/small_calibrate.prm";
  for (const auto model : cases::all_values<cases::CalibrationModel>()) {
    TemporaryDirectory dir;
    const auto r = testing::run_msfem(
        "calibrate " + calibrate_case + " --quiet --json --no-compare --max-evaluations 2" +
        " --set \"calibration/variant=single_layer\" --set \"calibration/fit groups=\"" +
        " --set \"calibration/model=" + name_of(model) + "\" --out " + (dir / "c").string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto json = nlohmann::json::parse(r.out);
    EXPECT_EQ(json.at("variant"), "single_layer");
    EXPECT_EQ(json.at("model"), name_of(model));
  }
}

}  // namespace
}  // namespace msfem::compare
