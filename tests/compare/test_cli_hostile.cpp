// Hostile input, as a user gives it: every case is refused with exit 2, one error line naming the
// file, line or key at fault, no result folder, and no FEM solve before the check that refuses it.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cli_runner.hpp"

namespace msfem {
namespace {

using testing::run_msfem;
using testing::TemporaryDirectory;

const std::string cases_dir = MSFEM_CASES_DIR;
const std::string sphere_indent_case = cases_dir + "/sphere_indent.prm";

struct Hostile {
  const char* name;
  std::string args;      ///< after "msfem", with {dir} for the test's folder
  const char* expected;  ///< what the error line must name
};

class HostileInput : public ::testing::TestWithParam<Hostile> {};

void write(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

std::string replace_dir(std::string s, const std::string& dir) {
  for (auto at = s.find("{dir}"); at != std::string::npos; at = s.find("{dir}"))
    s.replace(at, 5, dir);
  return s;
}

TEST_P(HostileInput, IsRefusedAtOnceNamingTheFault) {
  const Hostile& h = GetParam();
  TemporaryDirectory dir;
  write(dir / "self.prm", "include self.prm\n");
  write(dir / "a.prm", "include " + (dir / "b.prm").string() + "\n");
  write(dir / "b.prm", "include " + (dir / "a.prm").string() + "\n");
  write(dir / "twice.prm",
        "subsection material\n  set youngs modulus = 3000\n  set youngs  modulus = 4000\nend\n");
  write(dir / "empty.prm", "");
  const auto out = dir / "out";
  const std::string args = replace_dir(h.args, dir.path().string());
  // run, sweep and calibrate write a folder (--out); simplify and bench take none.
  const bool folder =
      args.find("--out") == std::string::npos &&
      (args.rfind("run", 0) == 0 || args.rfind("sweep", 0) == 0 || args.rfind("calibrate", 0) == 0);
  const auto r = run_msfem(args + (folder ? " --out " + out.string() : std::string()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  std::size_t error_lines = 0;
  std::string error;
  std::istringstream lines(r.err);
  for (std::string line; std::getline(lines, line);)
    if (line.find(": error: ") != std::string::npos) {
      ++error_lines;
      error = line;
    }
  EXPECT_EQ(error_lines, 1u) << r.err;
  EXPECT_NE(error.find(h.expected), std::string::npos) << error;
  EXPECT_EQ(r.err.find("solving the FEM"), std::string::npos) << "solved before refusing";
  EXPECT_FALSE(std::filesystem::exists(out));
  // Nothing else either: no temporary, claim or half-written file.
  // (The FEM cache's folder is made, empty, where the run would keep it.)
  for (const auto& entry : std::filesystem::directory_iterator(dir.path()))
    EXPECT_TRUE(entry.path().extension() == ".prm" ||
                (entry.path().filename() == ".fem-cache" && std::filesystem::is_empty(entry)))
        << entry.path();
}

const Hostile hostile[] = {
    {"SelfInclude", "run {dir}/self.prm", "self.prm:1: include"},
    {"MutualInclude", "run {dir}/a.prm", "includes itself"},
    {"KeySetTwice", "run {dir}/twice.prm", "twice.prm:3: 'material/youngs modulus' is set twice"},
    {"EmptyCaseFile", "run {dir}/empty.prm", "empty.prm: the case file is empty"},
    {"DirectoryAsCase", "run {dir}", "is a directory"},
    {"CellSizeThatWouldMeshForever", "run " + sphere_indent_case + " --set 'fem/cell size=1e-4'",
     "fem/cell size 0.0001 m would mesh about"},
    {"MisspelledGroupScale",
     "run " + sphere_indent_case + " --set 'mass spring/group scales=tier1_edgez:2'",
     "mass spring/group scales: no variant of the case has a group 'tier1_edgez'"},
    {"VolumeScaleWithoutVolume",
     "run " + sphere_indent_case + " --set 'mass spring/group scales=volume:2'",
     "volume preservation = true"},
    {"AbsurdModulus", "run " + sphere_indent_case + " --set 'material/youngs modulus=1e300'",
     "material/youngs modulus=1e300"},
    {"SimplifyAboveTheVertexCount",
     "run " + sphere_indent_case + " --set 'geometry/simplify to vertices=5000'",
     "geometry/simplify to vertices = 5000 is more than the 642 vertices"},
    {"MoreControlPointsThanVertices",
     "run " + sphere_indent_case + " --set 'mass spring/skeleton/control points=5000'",
     "mass spring/skeleton/control points = 5000"},
    {"FixedRegionCatchingNoNode",
     "run " + sphere_indent_case + " --set 'support/inner core scale=50'",
     "support/fixed region: it catches no node"},
    // Under gravity alone, a fixed ball that holds no mesh node: the FEM would be singular (an
    // iterative solver's fallback once returned 44 mm on a 50 mm sphere for such a case).
    {"SingularFemFromATinyFixedRegion",
     "run " + sphere_indent_case +
         " --set loads/tool/enabled=false --set 'loads/gravity=0,0,-9.81' --set 'support/fixed "
         "region=sphere' --set 'support/sphere radius=1e-4'",
     "support/fixed region"},
    {"UnknownIntegrator", "run " + sphere_indent_case + " --set 'timing/integrator=verlet'",
     "verlet"},
    {"UnknownPrecision", "run " + sphere_indent_case + " --set 'timing/precision=half'", "half"},
    {"PathStepThatWouldPressForever",
     "run " + sphere_indent_case + " --set 'loads/tool/path step=1e-9'", "loads/tool/path step"},
    {"ErrorEstimateDegreeAtP2", "run " + sphere_indent_case + " --set 'fem/error estimate=degree'",
     "fem/error estimate = degree needs fem/degree = 1"},
    {"UnknownFitGroup", "calibrate " + sphere_indent_case + " --fit nope", "has no group 'nope'"},
    {"HeldOutLoadOnATrainingVertex",
     "calibrate " + sphere_indent_case + " --train '0,0,1@0.005' --test '0,0.001,1@0.005'",
     "presses the same surface vertex"},
    {"EmptyOutPath", "run " + sphere_indent_case + " --out ''", "empty path"},
    // Numbers each key accepts alone that the case makes meaningless, refused before the FEM.
    {"ToolDepthAtRoundOff", "run " + sphere_indent_case + " --set loads/tool/depth=1e-7",
     "loads/tool/depth = 1e-07 m is below"},
    {"ToolDepthOfADenormal", "run " + sphere_indent_case + " --set loads/tool/depth=1e-300",
     "loads/tool/depth = 1e-300 m is below"},
    {"CurveDepthZero", "run " + sphere_indent_case + " --set 'loads/tool/curve depths=0,0.005'",
     "loads/tool/curve depths = 0 m is below"},
    {"GravityOfAThousandG", "run " + sphere_indent_case + " --set 'loads/gravity=0,0,-1e4'",
     "loads/gravity would move the surface about"},
    {"PatchForceOfAMegaNewton",
     "run " + sphere_indent_case +
         " --set 'loads/patch force/enabled=true' --set 'loads/patch force/force=1e6,0,0'",
     "loads/patch force/force would move the surface about"},
    {"TimeStepAtRoundOff", "run " + sphere_indent_case + " --set timing/dt=1e-300",
     "timing/dt = 1e-300 s is below"},
    {"HuTableOfADenormalModulus",
     "run " + sphere_indent_case + " --set 'material/youngs modulus image=" + cases_dir +
         "/data/abdomen_ct_3mm.nii.gz' --set 'material/hu to youngs=0:1e-300; 100:3000'",
     "material/hu to youngs: 0:1e-300 gives E outside"},
    {"HuTableOfNoContrastLimit",
     "run " + sphere_indent_case + " --set 'material/youngs modulus image=" + cases_dir +
         "/data/abdomen_ct_3mm.nii.gz' --set 'material/hu to youngs=0:0.01; 100:1e11'",
     "a contrast above"},
    // Settings that would be ignored.
    {"HuTableWithoutImage",
     "run " + sphere_indent_case + " --set 'material/hu to youngs=0:3000; 100:5000'",
     "material/hu to youngs is set but material/youngs modulus image is empty"},
    {"RefinementSizeWithRefinementOff",
     "run " + sphere_indent_case + " --set 'mass spring/contact refinement/edge length=0.001'",
     "contact refinement: radius or edge length is set but enabled = false"},
    {"VolumePreservationWithoutVolumeElements",
     "run " + sphere_indent_case +
         " --set 'mass spring/variants=single_layer' --set 'mass spring/volume preservation=true'",
     "none of mass spring/variants has volume elements"},
    {"UnitOfAGeneratedSurface", "run " + sphere_indent_case + " --set geometry/unit=mm",
     "geometry/unit = mm has no effect on a generated surface"},
    {"SweepOfNoResolution", "sweep " + sphere_indent_case + " --resolutions ''",
     "option --resolutions: '' lists no value"},
    {"RepeatedOption", "sweep " + sphere_indent_case + " --resolutions 2 --resolutions 3",
     "option --resolutions is given twice"},
    {"BenchOnAHundredThousandThreads", "bench massspring --threads 100000",
     "option --threads 100000 is outside [1, 256]"},
    {"BenchOfACaseItDoesNotHave", "bench massspring --cases seed_sphere,brain",
     "option --cases: no bench case 'brain' (seed_sphere, brain_scale"},
    {"BenchOfNoCase", "bench massspring --cases ''", "option --cases: '' lists no case"},
    {"BenchOfACaseNamedTwice", "bench massspring --cases seed_sphere,seed_sphere",
     "option --cases: 'seed_sphere' is named twice"},
    {"SimplifySmoothedAMillionTimes",
     "simplify " + cases_dir +
         "/data/pancreas_vh_female_m.obj {dir}/p.obj --vertices 446 "
         "--smooth 1000000",
     "option --smooth 1000000 is outside [0, 1000]"},
    {"SimplifyOntoItsInput",
     "simplify " + cases_dir + "/data/pancreas_vh_female_m.obj " + cases_dir +
         "/data/pancreas_vh_female_m.obj --vertices 446",
     "is the input file"},
};

INSTANTIATE_TEST_SUITE_P(Cli, HostileInput, ::testing::ValuesIn(hostile),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(CliInterface, EveryCommandPrintsItsOptionsWithHelp) {
  for (const char* command : {"run", "sweep", "regress", "calibrate", "params", "mesh-info",
                              "simplify", "bench", "verify"}) {
    const auto r = run_msfem(std::string(command) + " --help");
    EXPECT_EQ(r.exit_code, 0) << command << r.err;
    EXPECT_NE(r.out.find(std::string("usage: msfem ") + command), std::string::npos) << r.out;
  }
  const auto run = run_msfem("run --help");
  for (const char* option : {"--no-timing", "--no-cache", "--no-curve", "--set", "--out"})
    EXPECT_NE(run.out.find(option), std::string::npos) << option;
}

TEST(CliInterface, AFullStandardOutputIsAFailure) {
  const int status =
      std::system((std::string(MSFEM_EXECUTABLE) + " params > /dev/full 2>/dev/null").c_str());
  EXPECT_EQ(WEXITSTATUS(status), 1);
}

// The printed language is a case: `msfem params > x.prm && msfem run x.prm` runs (P1 and no
// estimate here, to keep it short; every key else as printed).
TEST(CliInterface, ThePrintedDefaultsRun) {
  TemporaryDirectory dir;
  const auto params = run_msfem("params");
  ASSERT_EQ(params.exit_code, 0);
  write(dir / "defaults.prm", params.out);
  const auto r = run_msfem("run " + (dir / "defaults.prm").string() +
                           " --quiet --no-timing --no-curve --set fem/degree=1 --set "
                           "'fem/error estimate=none' --out " +
                           (dir / "run").string());
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

// A surface read in the wrong unit solves without error: msfem warns when it is not organ-sized.
TEST(CliInterface, ASurfaceInTheWrongUnitIsWarnedAbout) {
  TemporaryDirectory dir;
  const auto r = run_msfem("run " + sphere_indent_case + " --set 'geometry/source=" + cases_dir +
                           "/data/pancreas_vh_female_m.obj' --set geometry/unit=mm --out " +
                           (dir / "run").string());
  EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the surface spans 0.000"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("geometry/unit = mm"), std::string::npos) << r.err;
  EXPECT_EQ(r.exit_code, 2) << r.err;  // and the 5 mm tool is then deeper than the model
}

// A time step no variant can take: known only once each variant is built (after the FEM), then
// refused as the case's error, naming the key and every variant's failure, with no run folder.
TEST(CliInterface, ATimeStepNoVariantCanTakeIsTheCasesError) {
  TemporaryDirectory dir;
  const auto r = run_msfem("run " + std::string(MSFEM_TEST_DATA_DIR) +
                           "/small_sphere.prm --quiet --no-curve --no-cache --set timing/dt=1 "
                           "--out " +
                           (dir / "run").string());
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("small_sphere.prm: timing/dt = 1"), std::string::npos) << r.err;
  for (const char* variant : {"three_tier:", "single_layer:", "tet_edges:", "skeleton:"})
    EXPECT_NE(r.err.find(variant), std::string::npos) << variant;
  EXPECT_FALSE(std::filesystem::exists(dir / "run"));
}

}  // namespace
}  // namespace msfem
