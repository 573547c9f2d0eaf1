#pragma once
// CGAL's alpha wrap, kept in its own translation unit: its Delaunay machinery is the slowest
// header set in the library to compile, and only repair needs it.

#include "msfem/cases/surface.hpp"

namespace msfem::cases::detail {

/// A closed, 2-manifold, self-intersection-free surface enclosing the triangles of `soup` (which
/// need be neither closed nor manifold) at `offset` from them, with no cavity narrower than
/// `alpha` entered (CGAL alpha_wrap_3, both in the soup's length unit).
Surface alpha_wrap_surface(const Surface& soup, double alpha, double offset);

}  // namespace msfem::cases::detail
