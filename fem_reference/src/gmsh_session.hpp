#pragma once

#include <cstddef>
#include <mutex>

#include "msfem/fem_reference/volume_mesh.hpp"

namespace msfem::fem_reference::detail {

/// Gmsh is a process-wide singleton: a session initialises it quietly for one meshing job, holds a
/// lock so that two jobs never share it, and finalises it on exit from the scope (also when a
/// meshing call throws).
class GmshSession {
 public:
  GmshSession();
  ~GmshSession();
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;

 private:
  std::lock_guard<std::mutex> lock_;
};

/// Runs Gmsh's 3D mesher and returns current_tetrahedra(). Where the worst cell's quality
/// (cell_quality) is below `relocate_below_quality`, Gmsh's "Relocate3D" pass first moves the
/// volume's own vertices (never boundary ones) to raise the worst cells' quality.
VolumeMesh generate_tetrahedra(std::size_t num_kept_nodes, double relocate_below_quality = 0.0);

/// Gmsh's linear tetrahedra now. Nodes with tags 1..num_kept_nodes come first, in tag order (the
/// given surface's vertices); the other nodes used by a tetrahedron follow in tag order.
/// Tetrahedra are reoriented to positive volume.
VolumeMesh current_tetrahedra(std::size_t num_kept_nodes);

}  // namespace msfem::fem_reference::detail
