#pragma once

// Minimal Wavefront OBJ reader for the benchmark: `v x y z` and `f a b c` lines (1-based, the
// `a/b/c` forms accepted), polygons fan-triangulated. The full reader lives in cases/.

#include <Eigen/Core>
#include <optional>
#include <string>

namespace msfem::massspring::bench {

struct ObjSurface {
  Eigen::MatrixX3d vertices;
  Eigen::MatrixX3i triangles;
};

/// Reads the file and multiplies coordinates by `metres_per_unit`; std::nullopt if it is missing.
/// Throws std::runtime_error naming the line for a malformed one.
std::optional<ObjSurface> read_obj(const std::string& path, double metres_per_unit);

}  // namespace msfem::massspring::bench
