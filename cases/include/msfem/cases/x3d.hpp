#pragma once
// X3D 3.3 (ISO/IEC 19775, XML encoding) triangle surfaces: an IndexedFaceSet with its Coordinate
// (and per-vertex Color) inside a Shape, as the layered brain paper's X3D scene and X3DOM have
// them. msfem reads one as a surface source (.x3d, like an .obj) and writes its runs' scene.x3d.

#include <Eigen/Core>
#include <filesystem>
#include <string>

#include "msfem/cases/surface.hpp"
#include "msfem/cases/xml_text.hpp"

namespace msfem::cases {

/// The IndexedFaceSet of the Shape whose DEF is `def` (empty: the file's first IndexedFaceSet):
/// its Coordinate points (in the file's units) and its faces, polygons fan-triangulated. Every
/// fault is an InputError naming the file and the node or index: not XML, no such Shape, no
/// Coordinate, a point that is not three finite numbers, an index out of range, a face of fewer
/// than three.
Surface read_x3d_surface(const std::filesystem::path& file, const std::string& def = "");

/// The same from bytes (what read_surface and the fuzz target call).
Surface read_x3d_surface_bytes(const std::filesystem::path& file, const std::string& bytes,
                               const std::string& def = "");

/// A `<Shape DEF="def">` holding the surface as an IndexedFaceSet (solid false, every coordinate
/// to 17 significant digits so it reads back exactly), with per-vertex colours (n x 3 in [0, 1])
/// when `colours` has rows, and `appearance` (an <Appearance> element, or empty) before it. Every
/// element has its end tag, so the same text is XML and HTML (which has no `<Name .../>`);
/// `attributes` (e.g. an HTML page's id) go into the Shape's start tag.
std::string x3d_shape(const std::string& def, const Eigen::MatrixX3d& points,
                      const Eigen::MatrixX3i& triangles, const Eigen::MatrixX3d& colours,
                      const std::string& appearance, const std::string& indent,
                      const std::string& attributes = "");

}  // namespace msfem::cases
