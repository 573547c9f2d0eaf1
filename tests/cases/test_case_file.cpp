#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/cases/errors.hpp"
#include "msfem/cases/setting_names.hpp"
#include "msfem/massspring/integrators.hpp"

namespace msfem::cases {
namespace {

class CaseFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("msfem_case_" + std::to_string(std::random_device{}()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::filesystem::path write(const std::string& name, const std::string& text) {
    const auto p = dir_ / name;
    std::ofstream(p) << text;
    return p;
  }

  // The message of the InputError thrown by read_case, or "" if none was.
  std::string error_of(const std::filesystem::path& p, const std::vector<std::string>& sets = {}) {
    try {
      read_case(p, sets);
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
      return e.what();
    }
    return "";
  }

  std::filesystem::path dir_;
};

TEST_F(CaseFile, ReadsEverySectionAndResolvesTheSurfaceBesideTheCase) {
  const auto p = write("brainy.prm", R"(# a comment
subsection geometry
  set source = meshes/brain.obj
  set unit = mm
  set simplify to vertices = 9177
end
subsection material
  set youngs modulus = 1400
  set poisson ratio = 0.49
end
subsection support
  set fixed region = half space
  set half space normal = 0, 0, -2
end
subsection loads
  set gravity = 0, 0, -9.81
  subsection tool
    set directions = 0,0,1; 1,0,0
    set depth = 0.004
    set curve depths = 0.001, 0.002
  end
end
subsection mass spring
  set variants = three_tier, skeleton
  set group scales = tier1_edges:1.5, links:0.5
  subsection three tier
    set inner tiers = offset
  end
end
subsection fem
  set degree = 1
end
)");
  const CaseParameters c = read_case(p);
  EXPECT_EQ(c.name, "brainy");
  EXPECT_EQ(c.geometry.source, (dir_ / "meshes/brain.obj").string());
  EXPECT_EQ(c.geometry.unit, LengthUnit::millimetre);
  EXPECT_EQ(c.geometry.simplify_to_vertices, 9177);
  EXPECT_DOUBLE_EQ(c.material.youngs_modulus_pa, 1400);
  EXPECT_DOUBLE_EQ(c.material.poisson_ratio, 0.49);
  EXPECT_DOUBLE_EQ(c.material.density_kg_per_m3, 1040);  // default
  EXPECT_EQ(c.support.kind, SupportParameters::Kind::half_space);
  EXPECT_TRUE(c.support.half_space_normal.isApprox(Eigen::Vector3d(0, 0, -1)));
  EXPECT_DOUBLE_EQ(c.loads.gravity_m_per_s2.z(), -9.81);
  ASSERT_EQ(c.loads.tool.directions.size(), 2u);
  EXPECT_TRUE(c.loads.tool.directions[1].isApprox(Eigen::Vector3d::UnitX()));
  EXPECT_DOUBLE_EQ(c.loads.tool.depth_m, 0.004);
  EXPECT_EQ(c.loads.tool.curve_depths_m, (std::vector<double>{0.001, 0.002}));
  EXPECT_EQ(c.mass_spring.variants, (std::vector<Variant>{Variant::three_tier, Variant::skeleton}));
  ASSERT_EQ(c.mass_spring.group_scales.size(), 2u);
  EXPECT_EQ(c.mass_spring.group_scales[0].first, "tier1_edges");
  EXPECT_DOUBLE_EQ(c.mass_spring.group_scales[1].second, 0.5);
  EXPECT_EQ(c.mass_spring.inner_tiers, massspring::InnerTierMethod::normal_offset);
  EXPECT_EQ(c.fem.degree, 1);
}

TEST_F(CaseFile, UnknownKeyNamesFileAndLine) {
  const auto p = write("typo.prm",
                       "subsection material\n  set youngs modulus = 1\n"
                       "  set poison ratio = 0.3\nend\n");
  const std::string e = error_of(p);
  EXPECT_NE(e.find("typo.prm:3:"), std::string::npos) << e;
  EXPECT_NE(e.find("poison ratio"), std::string::npos) << e;
}

TEST_F(CaseFile, UnknownSectionAndOutOfRangeValuesNameFileAndLine) {
  const std::string section = error_of(write("sec.prm", "\nsubsection materials\nend\n"));
  EXPECT_NE(section.find("sec.prm:2:"), std::string::npos) << section;

  const std::string range =
      error_of(write("nu.prm", "subsection material\n  set poisson ratio = 0.6\nend\n"));
  EXPECT_NE(range.find("nu.prm:2:"), std::string::npos) << range;
  EXPECT_NE(range.find("0.6"), std::string::npos) << range;

  const std::string variant = error_of(
      write("v.prm", "subsection mass spring\n  set variants = three_tier, four_tier\nend\n"));
  EXPECT_NE(variant.find("v.prm:2:"), std::string::npos) << variant;

  const std::string zero_e =
      error_of(write("e.prm", "subsection material\n  set youngs modulus = 0\nend\n"));
  EXPECT_NE(zero_e.find("youngs modulus"), std::string::npos) << zero_e;

  EXPECT_NE(error_of(dir_ / "absent.prm").find("absent.prm"), std::string::npos);
}

TEST_F(CaseFile, CommandLineOverridesAreTypedToo) {
  const auto p = write("base.prm", "subsection material\n  set youngs modulus = 1400\nend\n");
  const CaseParameters c =
      read_case(p, {"material/youngs modulus=2500", "loads/tool/depth=0.002", "fem/degree=1"});
  EXPECT_DOUBLE_EQ(c.material.youngs_modulus_pa, 2500);
  EXPECT_DOUBLE_EQ(c.loads.tool.depth_m, 0.002);
  EXPECT_EQ(c.fem.degree, 1);

  EXPECT_NE(error_of(p, {"material/youngs=1"}).find("--set 'material/youngs=1'"),
            std::string::npos);
  EXPECT_NE(error_of(p, {"fem/degree=3"}).find("fem/degree=3"), std::string::npos);
  EXPECT_NE(error_of(p, {"nosuch/key=1"}).find("nosuch"), std::string::npos);
  EXPECT_NE(error_of(p, {"material/density"}).find("SECTION/KEY=VALUE"), std::string::npos);
}

TEST(CaseLanguage, DescribesEverySection) {
  const std::string text = describe_case_parameters();
  for (const char* s : {"geometry", "material", "support", "loads", "tool", "patch force",
                        "mass spring", "three tier", "skeleton", "fem", "timing", "output"})
    EXPECT_NE(text.find("subsection " + std::string(s)), std::string::npos) << s;
  EXPECT_NE(text.find("youngs modulus"), std::string::npos);
}

// The case language takes exactly the integrators massspring steps: every one is read back as
// given (central_difference, the skeleton paper's scheme, included) and a name massspring does not
// know is refused when the file is read, naming the file and line.
TEST_F(CaseFile, EveryIntegratorMassspringKnowsAndNoOther) {
  const auto p = write("c.prm", "subsection timing\n  set integrator = symplectic_euler\nend\n");
  for (massspring::IntegratorKind kind : massspring::all_integrators()) {
    const std::string name = massspring::to_string(kind);
    EXPECT_EQ(read_case(p, {"timing/integrator=" + name}).timing.integrator, kind);
  }
  EXPECT_EQ(massspring::to_string(massspring::parse_integrator("central_difference")),
            "central_difference");
  const auto bad = write("bad.prm", "subsection timing\n  set integrator = verlet\nend\n");
  const std::string error = error_of(bad);
  EXPECT_NE(error.find("bad.prm:2"), std::string::npos) << error;  // file:line
  EXPECT_NE(error.find("verlet"), std::string::npos) << error;
}

// timing/precision: double unless float is asked for; anything else is refused naming the key.
TEST_F(CaseFile, TimingPrecisionIsDoubleOrFloat) {
  const auto p = write("c.prm", "subsection timing\n  set integrator = implicit_euler\nend\n");
  EXPECT_FALSE(read_case(p).timing.single_precision);
  EXPECT_TRUE(read_case(p, {"timing/precision=float"}).timing.single_precision);
  EXPECT_FALSE(read_case(p, {"timing/precision=double"}).timing.single_precision);
  const auto bad = write("bad.prm", "subsection timing\n  set precision = half\nend\n");
  const std::string error = error_of(bad);
  EXPECT_NE(error.find("bad.prm:2"), std::string::npos) << error;
  EXPECT_NE(error.find("half"), std::string::npos) << error;
}

TEST_F(CaseFile, ErrorEstimateMethodsAndTheirLimits) {
  const auto p = write("c.prm", "subsection fem\n  set degree = 1\nend\n");
  EXPECT_EQ(read_case(p).fem.error_estimate, FemParameters::ErrorEstimate::automatic);
  for (const char* name : {"auto", "refine", "degree", "none"}) {
    const FemParameters fem = read_case(p, {std::string("fem/error estimate=") + name}).fem;
    EXPECT_EQ(name_of(fem.error_estimate), name);
  }
  // P3 does not exist on tetrahedra: degree + 1 of a P2 reference is refused at once.
  const std::string error = error_of(p, {"fem/degree=2", "fem/error estimate=degree"});
  EXPECT_NE(error.find("c.prm"), std::string::npos) << error;
  EXPECT_NE(error.find("fem/error estimate"), std::string::npos) << error;
  EXPECT_NE(error_of(p, {"fem/error estimate=coarsen"}), "");
}

TEST_F(CaseFile, AMisspelledSectionIsNamedNotItsFirstKey) {
  const auto p = write("c.prm", "subsection materail\n  set youngs modulus = 2000\nend\n");
  const std::string error = error_of(p);
  EXPECT_NE(error.find("c.prm:1: unknown subsection 'materail'"), std::string::npos) << error;
  EXPECT_NE(error.find("material"), std::string::npos) << error;  // the sections it could be
  const auto nested =
      write("n.prm", "subsection loads\n  subsection tol\n    set radius = 0.01\n  end\nend\n");
  EXPECT_NE(
      error_of(nested).find("n.prm:2: unknown subsection 'loads/tol' (subsections of loads: "),
      std::string::npos)
      << error_of(nested);
}

TEST_F(CaseFile, AByteOrderMarkAndIncludesRelativeToTheCaseFile) {
  const auto p = write("bom.prm", "\xEF\xBB\xBFsubsection material\n  set density = 1000\nend\n");
  EXPECT_EQ(read_case(p).material.density_kg_per_m3, 1000.0);
  std::filesystem::create_directories(dir_ / "sub");
  write("sub/part.prm", "subsection material\n  set density = 900\nend\n");
  const auto main = write("sub/main.prm", "include part.prm\n");
  const auto cwd = std::filesystem::current_path();
  std::filesystem::current_path(dir_);  // not the case file's folder
  const double density = read_case(main).material.density_kg_per_m3;
  std::filesystem::current_path(cwd);
  EXPECT_EQ(density, 900.0);
}

TEST_F(CaseFile, OutputDirectoryWrittenInTheCaseIsRelativeToIt) {
  const auto p = write("c.prm", "subsection output\n  set directory = mine\nend\n");
  EXPECT_EQ(read_case(p).output.directory, (dir_ / "mine").lexically_normal().string());
  EXPECT_EQ(read_case(p, {"output/directory=there"}).output.directory, "there");  // as typed
  const auto d = write("d.prm", "subsection fem\n  set degree = 1\nend\n");
  EXPECT_EQ(read_case(d).output.directory, "results/runs");  // the default: the working dir
}

}  // namespace
}  // namespace msfem::cases
