#include "obj_surface.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace msfem::massspring::bench {

std::optional<ObjSurface> read_obj(const std::string& path, double metres_per_unit) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3i> faces;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    std::istringstream words(line);
    std::string tag;
    words >> tag;
    if (tag == "v") {
      Eigen::Vector3d p;
      if (!(words >> p.x() >> p.y() >> p.z()))
        throw std::runtime_error(path + ":" + std::to_string(number) + ": bad vertex");
      points.push_back(p * metres_per_unit);
    } else if (tag == "f") {
      std::vector<int> corners;
      std::string corner;
      while (words >> corner)
        corners.push_back(std::stoi(corner.substr(0, corner.find('/'))) - 1);
      if (corners.size() < 3)
        throw std::runtime_error(path + ":" + std::to_string(number) + ": face with < 3 corners");
      for (std::size_t k = 1; k + 1 < corners.size(); ++k)
        faces.emplace_back(corners[0], corners[k], corners[k + 1]);
    }
  }
  ObjSurface surface;
  surface.vertices.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i)
    surface.vertices.row(i) = points[i].transpose();
  surface.triangles.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t f = 0; f < faces.size(); ++f)
    surface.triangles.row(f) = faces[f].transpose();
  return surface;
}

}  // namespace msfem::massspring::bench
