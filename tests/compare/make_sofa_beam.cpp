// make_sofa_beam OUTDIR: writes SOFA's MeshSpringForceField beam (40 x 10 x 10 nodes, 1 cm apart)
// as beam.vtu and beam.xs3, and beam.prm, the case that compares both with the FEM under gravity
// (results/BENCHMARKS.md, "A network in SOFA's layout").
#include <filesystem>
#include <iostream>

#include "sofa_beam.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: make_sofa_beam OUTDIR\n";
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);
  const auto beam = msfem::testing::make_sofa_beam({});
  msfem::testing::write_sofa_beam_vtu(beam, dir / "beam.vtu");
  msfem::testing::write_sofa_beam_xsp(beam, dir / "beam.xs3");
  msfem::testing::write_sofa_beam_case(dir / "beam.prm", "beam.vtu", "vtu=beam.vtu; xsp=beam.xs3");
  std::cout << "beam: " << beam.points.rows() << " nodes, " << beam.springs.size() << " springs, "
            << beam.triangles.size() << " surface triangles in " << dir.string() << "\n";
  return 0;
}
