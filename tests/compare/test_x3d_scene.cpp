// The run's scene: scene.x3d is well-formed X3D 3.3 whose surfaces read back into msfem as the
// run's surfaces, and scene.html, opened in headless Chromium, draws the organ in the error
// colours (skipped, saying why, where Chromium is not installed).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "cli_runner.hpp"
#include "msfem/cases/x3d.hpp"
#include "msfem/compare/writers/error_picture.hpp"
#include "msfem/compare/writers/fields_h5.hpp"
#include "png_reader.hpp"

namespace msfem {
namespace {

using testing::read_text;
using testing::run_msfem;
using testing::TemporaryDirectory;

class X3dScene : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TemporaryDirectory;
    const auto r = run_msfem(std::string("run ") + MSFEM_CASES_DIR +
                             "/sphere_indent.prm --set geometry/source=icosphere:3:0.05 --set "
                             "fem/degree=1 --set 'fem/error estimate=none' --quiet --no-timing "
                             "--set 'mass spring/variants=three_tier,single_layer' --out " +
                             run().string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static void TearDownTestSuite() { delete dir_; }
  static std::filesystem::path run() { return *dir_ / "run"; }
  static inline TemporaryDirectory* dir_ = nullptr;
};

bool program_runs(const std::string& command) {
  return std::system((command + " > /dev/null 2>&1").c_str()) == 0;
}

TEST_F(X3dScene, IsX3dThatReadsBackAsTheRunsSurfaces) {
  const auto scene = run() / "scene.x3d";
  const std::string text = read_text(scene);
  for (const char* node :
       {"<X3D profile=\"Interchange\" version=\"3.3\">", "<Scene>", "<Viewpoint DEF=\"view_along\"",
        "<Viewpoint DEF=\"view_side\"", "<IndexedFaceSet",
        "<Coordinate point=", "<Color color=", "<Sphere radius=\"0.005"})
    EXPECT_NE(text.find(node), std::string::npos) << node;
  if (program_runs("xmllint --version"))
    EXPECT_TRUE(program_runs("xmllint --noout " + scene.string()));
  else
    std::cout << "xmllint is not installed (Debian: libxml2-utils): well-formedness unchecked\n";
  const auto h5 = run() / "fields.h5";
  const cases::Surface rest = cases::read_x3d_surface(scene, "undeformed");
  const Eigen::Index n = rest.num_vertices();
  ASSERT_EQ(n, 642);
  for (const char* variant : {"three_tier", "single_layer"}) {
    const cases::Surface deformed = cases::read_x3d_surface(scene, variant);
    const Eigen::MatrixXd u =
        compare::read_h5_matrix(h5, std::string("/variants/") + variant + "/displacement");
    ASSERT_EQ(deformed.num_vertices(), n) << variant;
    EXPECT_EQ(deformed.triangles, rest.triangles) << variant;
    EXPECT_LE((deformed.vertices - rest.vertices - u).cwiseAbs().maxCoeff(), 1e-9) << variant;
  }
  // The undeformed surface is the case's: the icosphere's vertices on its radius.
  EXPECT_LE(std::abs(rest.vertices.rowwise().norm().maxCoeff() - 0.05), 1e-9);
}

TEST_F(X3dScene, ChromiumDrawsTheOrganInTheErrorColours) {
  std::string chromium;
  for (const char* name : {"chromium", "chromium-browser", "google-chrome"})
    if (program_runs(std::string(name) + " --version")) chromium = name;
  if (chromium.empty())
    GTEST_SKIP() << "no headless Chromium (scripts/install-deps.sh installs Debian's chromium "
                    "where it can): scene.html is not drawn here";
  const auto shot = *dir_ / "shot.png";
  ASSERT_TRUE(program_runs(chromium +
                           " --headless=new --no-sandbox --disable-gpu --use-angle=swiftshader "
                           "--enable-unsafe-swiftshader --window-size=1100,900 "
                           "--virtual-time-budget=15000 --screenshot=" +
                           shot.string() + " file://" + (run() / "scene.html").string()));
  const testing::Image image = testing::read_png(shot);
  ASSERT_GT(image.width, 0);
  // Pixels on the error scale (within 24 of a colour of it, per channel), and how far up it.
  int on_scale = 0, high = 0;
  for (int row = 0; row < image.height; row += 2)
    for (int column = 0; column < image.width; column += 2) {
      const auto p = image.at(column, row);
      for (int k = 0; k <= 100; ++k) {
        const Eigen::Vector3d c = 255.0 * compare::error_colour(k / 100.0);
        if (std::abs(p[0] - c[0]) < 24 && std::abs(p[1] - c[1]) < 24 &&
            std::abs(p[2] - c[2]) < 24) {
          ++on_scale;
          high += k >= 40;
          break;
        }
      }
    }
  // The sphere fills about a fifth of the 1000 x 650 canvas (every second pixel counted): its
  // far field in the scale's low colours and the tool's neighbourhood in its upper half.
  EXPECT_GT(on_scale, 10000) << "of " << image.width * image.height / 4;
  EXPECT_GT(high, 100);
}

}  // namespace
}  // namespace msfem
