// msfem under mpirun: two ranks share the variants (run) and the loads (calibrate) and give the
// one-rank answer, printed once and written once.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_runner.hpp"

namespace msfem {
namespace {

using testing::read_text;
using testing::run_msfem;
using testing::TemporaryDirectory;

// Two tool positions, so that each rank presses every variant at one of them; no dynamics timed.
const std::string small_two_loads = std::string(MSFEM_TEST_DATA_DIR) +
                                    "/small_sphere.prm --no-timing --no-cache --quiet "
                                    "--set \"loads/tool/directions=0,0,1; 1,0,0.3\"";

std::string find_mpirun() {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  std::string dir;
  while (std::getline(dirs, dir, ':'))
    if (!dir.empty() && std::filesystem::exists(std::filesystem::path(dir) / "mpirun"))
      return (std::filesystem::path(dir) / "mpirun").string();
  return {};
}

// `mpirun -np 2 msfem ARGS`, allowed as root and on a machine with fewer cores than ranks.
testing::CommandResult run_msfem_on_two_ranks(const std::string& mpirun, const std::string& args) {
  TemporaryDirectory tmp;
  const auto out = tmp / "out.txt", err = tmp / "err.txt";
  const std::string cmd =
      "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "
      "OMPI_MCA_rmaps_base_oversubscribe=1 " +
      mpirun + " -np 2 " + MSFEM_EXECUTABLE + " " + args + " >" + out.string() + " 2>" +
      err.string();
  const int status = std::system(cmd.c_str());
  testing::CommandResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = read_text(out);
  r.err = read_text(err);
  return r;
}

std::size_t occurrences(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1))
    ++n;
  return n;
}

// What differs between two correct runs: how long things took, how many ranks and iterations.
bool describes_the_run_not_the_result(const std::string& key) {
  return key == "mpi_ranks" || key.find("time_s") != std::string::npos ||
         key.find("iterations") != std::string::npos;
}

// Every number of `a` equals `b`'s within `tolerance` relative to the larger (absolute below 1e-12,
// the noise of a converged solve on a value that is zero); counts the numbers compared. The FEM's
// estimate of its own error is a difference of two solves that each stop at the solver's
// tolerance, so it agrees to 1e-4 only.
void expect_same_numbers(const nlohmann::json& a, const nlohmann::json& b, const std::string& where,
                         double tolerance, int& compared) {
  ASSERT_EQ(a.type(), b.type()) << where;
  if (a.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    const double scale = std::max({std::abs(x), std::abs(y), 1e-12 / tolerance});
    EXPECT_LE(std::abs(x - y), tolerance * scale) << where << ": " << x << " vs " << y;
    ++compared;
  } else if (a.is_object()) {
    for (const auto& [key, value] : a.items()) {
      if (describes_the_run_not_the_result(key)) continue;
      ASSERT_TRUE(b.contains(key)) << where << "/" << key;
      const double t = key.rfind("estimated_", 0) == 0 ? std::max(tolerance, 1e-4) : tolerance;
      expect_same_numbers(value, b[key], where + "/" + key, t, compared);
    }
  } else if (a.is_array()) {
    ASSERT_EQ(a.size(), b.size()) << where;
    for (std::size_t i = 0; i < a.size(); ++i)
      expect_same_numbers(a[i], b[i], where + "/" + std::to_string(i), tolerance, compared);
  }
}

TEST(CliMpi, TwoRanksPrintOnceWriteOneFolderAndMatchOneRank) {
  const std::string mpirun = find_mpirun();
  if (mpirun.empty()) GTEST_SKIP() << "mpirun is not on PATH";
  TemporaryDirectory one, two;
  const auto alone = run_msfem("run " + small_two_loads + " --out " + (one / "run").string());
  ASSERT_EQ(alone.exit_code, 0) << alone.err;
  // Not quiet: the progress lines must come from one rank only.
  std::string args = "run " + small_two_loads + " --out " + (two / "run").string();
  args.replace(args.find(" --quiet"), 8, "");
  const auto shared = run_msfem_on_two_ranks(mpirun, args);
  ASSERT_EQ(shared.exit_code, 0) << shared.err;

  EXPECT_EQ(occurrences(shared.err, "msfem: loading the surface"), 1u) << shared.err;
  EXPECT_EQ(occurrences(shared.err, "shared across 2 ranks"), 1u) << shared.err;
  EXPECT_EQ(occurrences(shared.out, "results in "), 1u) << shared.out;
  EXPECT_EQ(occurrences(shared.out, "| tet_edges"), 1u) << shared.out;
  int entries = 0;
  for (const auto& entry : std::filesystem::directory_iterator(two.path())) {
    EXPECT_EQ(entry.path().filename(), "run");
    ++entries;
  }
  EXPECT_EQ(entries, 1);

  const auto a = nlohmann::json::parse(read_text(one / "run" / "summary.json"));
  const auto b = nlohmann::json::parse(read_text(two / "run" / "summary.json"));
  EXPECT_EQ(a["fem"]["mpi_ranks"], 1);
  EXPECT_EQ(b["fem"]["mpi_ranks"], 2);
  ASSERT_EQ(b["variants"].size(), 4u);
  ASSERT_EQ(b["fem"]["loads"].size(), 2u);
  ASSERT_EQ(b["variants"][0]["loads"]["per_tool"].size(), 2u);
  int compared = 0;
  // The FEM's iterative solve stops at its tolerance on either partition, so the variants' errors
  // against it agree to that, not bit for bit.
  expect_same_numbers(a, b, "summary.json", 1e-6, compared);
  EXPECT_GT(compared, 200);
}

TEST(CliMpi, EveryVariantIsTimedOnTwoRanksWithTheOneRankStableStep) {
  const std::string mpirun = find_mpirun();
  if (mpirun.empty()) GTEST_SKIP() << "mpirun is not on PATH";
  TemporaryDirectory one, two;
  const std::string timed =
      std::string(MSFEM_TEST_DATA_DIR) +
      "/small_sphere.prm --quiet --no-curve --set \"timing/steps=200\" --out ";
  const auto alone = run_msfem("run " + timed + (one / "run").string());
  ASSERT_EQ(alone.exit_code, 0) << alone.err;
  const auto shared = run_msfem_on_two_ranks(mpirun, "run " + timed + (two / "run").string());
  ASSERT_EQ(shared.exit_code, 0) << shared.err;
  const auto a = nlohmann::json::parse(read_text(one / "run" / "summary.json"));
  const auto b = nlohmann::json::parse(read_text(two / "run" / "summary.json"));
  ASSERT_EQ(a["variants"].size(), b["variants"].size());
  for (std::size_t v = 0; v < b["variants"].size(); ++v) {
    const auto& x = a["variants"][v];
    const auto& y = b["variants"][v];
    EXPECT_GT(y["steps_per_second"].get<double>(), 0.0) << y["name"];
    // Bisected on the same model from the same equilibrium: the same step, whichever rank timed it.
    EXPECT_NEAR(y["stable_dt_s"].get<double>(), x["stable_dt_s"].get<double>(),
                1e-6 * x["stable_dt_s"].get<double>())
        << y["name"];
  }
}

// msfem sweep on two ranks: the timed items are dealt out and every rank gets every point back,
// so rank 0 writes the one-rank sweep (its errors to the FEM's tolerance, its stable steps
// bisected alike), each point once and in order.
TEST(CliMpi, SweepOnTwoRanksListsTheOneRankPoints) {
  const std::string mpirun = find_mpirun();
  if (mpirun.empty()) GTEST_SKIP() << "mpirun is not on PATH";
  TemporaryDirectory one, two;
  const std::string sweep = "sweep " + std::string(MSFEM_TEST_DATA_DIR) +
                            "/small_sphere.prm --quiet --resolutions 1,2 "
                            "--integrators symplectic_euler,implicit_euler --out ";
  const auto alone = run_msfem(sweep + (one / "sweep").string());
  ASSERT_EQ(alone.exit_code, 0) << alone.err;
  const auto shared = run_msfem_on_two_ranks(mpirun, sweep + (two / "sweep").string());
  ASSERT_EQ(shared.exit_code, 0) << shared.err;
  const auto a = nlohmann::json::parse(read_text(one / "sweep" / "sweep.json"))["points"];
  const auto b = nlohmann::json::parse(read_text(two / "sweep" / "sweep.json"))["points"];
  ASSERT_EQ(a.size(), 16u);  // 4 variants x 2 integrators x 2 resolutions
  ASSERT_EQ(b.size(), a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string where = "point " + std::to_string(i);
    for (const char* key : {"variant", "integrator", "stepper", "not_resolved_by_reference"})
      EXPECT_EQ(a[i][key], b[i][key]) << where << " " << key;
    for (const char* key : {"resolution", "surface_vertices", "nodes", "springs"})
      EXPECT_EQ(a[i][key], b[i][key]) << where << " " << key;
    for (const char* key : {"rel_l2_error", "reaction_force_rel_error", "stable_dt_s"})
      EXPECT_NEAR(b[i][key].get<double>(), a[i][key].get<double>(),
                  1e-6 * std::abs(a[i][key].get<double>()))
          << where << " " << key;
    EXPECT_GT(b[i]["steps_per_second"].get<double>(), 0.0) << where;
  }
}

// msfem calibrate on two ranks: each rank solves its share of the loads at every evaluation, and
// the fit is the one-rank fit (the FEM references agree to the solver's tolerance, and a handful
// of evaluations keeps the optimiser on the same path).
TEST(CliMpi, CalibrateSharesTheLoadsAndFitsAsOneRank) {
  const std::string mpirun = find_mpirun();
  if (mpirun.empty()) GTEST_SKIP() << "mpirun is not on PATH";
  TemporaryDirectory one, two;
  const std::string args = "calibrate " + std::string(MSFEM_TEST_DATA_DIR) +
                           "/small_calibrate.prm --quiet --no-cache --no-compare "
                           "--max-evaluations 8 --out ";
  const auto alone = run_msfem(args + (one / "cal").string());
  ASSERT_EQ(alone.exit_code, 0) << alone.err;
  const auto shared = run_msfem_on_two_ranks(mpirun, args + (two / "cal").string());
  ASSERT_EQ(shared.exit_code, 0) << shared.err;
  const auto a = nlohmann::json::parse(read_text(one / "cal" / "calibration.json"));
  const auto b = nlohmann::json::parse(read_text(two / "cal" / "calibration.json"));
  ASSERT_EQ(b["after"]["train"].size(), 2u);
  ASSERT_EQ(b["after"]["test"].size(), 1u);
  int compared = 0;
  expect_same_numbers(a, b, "calibration.json", 1e-5, compared);
  EXPECT_GT(compared, 30);
}

// msfem regress on two ranks: the ranks share each case, rank 0 prints one table and writes every
// baseline, and the baselines are the one-rank ones.
TEST(CliMpi, RegressOnTwoRanksWritesTheOneRankBaselines) {
  const std::string mpirun = find_mpirun();
  if (mpirun.empty()) GTEST_SKIP() << "mpirun is not on PATH";
  TemporaryDirectory tmp;
  const std::string text = read_text(std::string(MSFEM_TEST_DATA_DIR) + "/small_sphere.prm");
  std::string cases;
  for (const char* name : {"first", "second"}) {
    std::ofstream(tmp / (std::string(name) + ".prm")) << text;
    cases += " " + (tmp / (std::string(name) + ".prm")).string();
  }
  const std::string update = "regress" + cases + " --quiet --update --baselines ";
  const auto alone = run_msfem(update + (tmp / "one").string());
  ASSERT_EQ(alone.exit_code, 0) << alone.err;
  const auto shared = run_msfem_on_two_ranks(mpirun, update + (tmp / "two").string());
  ASSERT_EQ(shared.exit_code, 0) << shared.err;
  for (const char* name : {"first", "second"}) {
    EXPECT_EQ(occurrences(shared.out, "/" + std::string(name) + ".json:"), 1u) << shared.out;
    const auto a = nlohmann::json::parse(read_text(tmp / "one" / (std::string(name) + ".json")));
    const auto b = nlohmann::json::parse(read_text(tmp / "two" / (std::string(name) + ".json")));
    EXPECT_TRUE(std::filesystem::exists(tmp / "two" / (std::string(name) + ".fields.h5")));
    int compared = 0;
    expect_same_numbers(a["variants"], b["variants"], name, 1e-6, compared);
    EXPECT_GT(compared, 20);
  }
  // The two-rank baselines pass against the one-rank run, and the table is printed once.
  const auto check = run_msfem_on_two_ranks(
      mpirun, "regress" + cases + " --quiet --baselines " + (tmp / "one").string());
  EXPECT_EQ(check.exit_code, 0) << check.out << check.err;
  EXPECT_EQ(occurrences(check.out, "regress: "), 1u) << check.out;
  EXPECT_EQ(occurrences(check.out, " 0 failed"), 1u) << check.out;
  EXPECT_GT(occurrences(check.out, "second"), 0u) << check.out;
}

TEST(CliMpi, BadInputOnTwoRanksExitsTwoOnceAndWritesNothing) {
  const std::string mpirun = find_mpirun();
  if (mpirun.empty()) GTEST_SKIP() << "mpirun is not on PATH";
  TemporaryDirectory tmp;
  // Found on every rank as the case is read.
  const auto bad_key = run_msfem_on_two_ranks(
      mpirun, "run " + small_two_loads + " --set \"fem/degree=7\" --out " + (tmp / "a").string());
  EXPECT_EQ(bad_key.exit_code, 2) << bad_key.err;
  EXPECT_EQ(occurrences(bad_key.err, "msfem run: error:"), 1u) << bad_key.err;
  // Found by rank 0 alone, which writes: the other rank must not go on to the FEM without it.
  std::filesystem::create_directories(tmp / "full");
  std::ofstream(tmp / "full" / "keep.txt") << "a user's file\n";
  const auto taken = run_msfem_on_two_ranks(
      mpirun, "run " + small_two_loads + " --out " + (tmp / "full").string());
  EXPECT_EQ(taken.exit_code, 2) << taken.err;
  EXPECT_EQ(occurrences(taken.err, "output folder exists and is not empty"), 1u) << taken.err;
  EXPECT_FALSE(std::filesystem::exists(tmp / "a"));
  EXPECT_EQ(read_text(tmp / "full" / "keep.txt"), "a user's file\n");
}

// The second run of a case takes its FEM from the cache, so rank 0 writes the reference's fields
// without having solved it: nothing it does there may wait for the other rank.
TEST(CliMpi, ASecondRunFromTheCacheEndsWithTheFirstRunsNumbers) {
  const std::string mpirun = find_mpirun();
  if (mpirun.empty()) GTEST_SKIP() << "mpirun is not on PATH";
  TemporaryDirectory tmp;
  const std::string args = "run " + std::string(MSFEM_TEST_DATA_DIR) +
                           "/small_sphere.prm --quiet --no-timing --set 'fem/error estimate=none'"
                           " --out ";
  const auto a = run_msfem_on_two_ranks(mpirun, args + (tmp / "A").string());
  ASSERT_EQ(a.exit_code, 0) << a.err;
  const auto b = run_msfem_on_two_ranks(mpirun, args + (tmp / "B").string());
  ASSERT_EQ(b.exit_code, 0) << b.err;
  const auto x = nlohmann::json::parse(read_text(tmp / "A" / "summary.json"));
  const auto y = nlohmann::json::parse(read_text(tmp / "B" / "summary.json"));
  EXPECT_FALSE(x["fem"]["from_cache"].get<bool>());
  EXPECT_TRUE(y["fem"]["from_cache"].get<bool>());
  int compared = 0;
  nlohmann::json xf = x, yf = y;
  xf["fem"].erase("from_cache");
  yf["fem"].erase("from_cache");
  expect_same_numbers(xf, yf, "summary.json", 1e-12, compared);
  EXPECT_GT(compared, 100);
  for (const auto& entry : std::filesystem::directory_iterator(tmp.path()))
    EXPECT_TRUE(entry.path().filename() == "A" || entry.path().filename() == "B" ||
                entry.path().filename() == ".fem-cache")
        << entry.path();
}

// A variant that fails on one rank while the other has nothing left to do: the job ends at once
// with the variant's message, whether the FEM was solved or read from the cache.
TEST(CliMpi, AFailingVariantWithACachedReferenceEndsPromptlyWithItsMessage) {
  const std::string mpirun = find_mpirun();
  if (mpirun.empty()) GTEST_SKIP() << "mpirun is not on PATH";
  TemporaryDirectory tmp;
  // A tool four times the organ's size: three_tier's Newton does not converge under it.
  const std::string args = "run " + std::string(MSFEM_CASES_DIR) +
                           "/sphere_indent.prm --quiet --no-timing --set "
                           "geometry/source=icosphere:2:0.05 --set fem/degree=1 --set 'fem/error "
                           "estimate=none' --set loads/tool/radius=0.2 --out ";
  for (const char* out : {"A", "B"}) {
    const auto start = std::chrono::steady_clock::now();
    const auto r = run_msfem_on_two_ranks(mpirun, args + (tmp / out).string());
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(r.exit_code, 1) << out << r.err;
    EXPECT_NE(r.err.find("variant three_tier failed: variant three_tier: Newton did not converge"),
              std::string::npos)
        << out << r.err;
    EXPECT_LT(seconds, 10.0) << out;
  }
}

}  // namespace
}  // namespace msfem
