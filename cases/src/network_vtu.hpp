#pragma once

// The parsed form of a VTK XML unstructured grid, shared by its reader and its coefficient
// rewriter (network_vtu.cpp, network_vtu_write.cpp); not installed.

#include <pugixml.hpp>
#include <string>
#include <string_view>

#include "network_detail.hpp"

namespace msfem::cases::detail {

struct VtuDocument {
  /// The XML pugixml parsed: the file with any appended data cut out. Its first `same_as_file`
  /// bytes are the file's own, so an element there is at the same offset in both.
  std::string xml;
  std::size_t same_as_file = 0;
  pugi::xml_document doc;
  pugi::xml_node cell_data;  ///< <CellData>, or empty
  VtkGrid grid;
};

/// Where the tag that starts at `open` ('<') ends: the index of its '>' outside quoted attribute
/// values, or text.size() where the text ends first.
std::size_t end_of_tag(std::string_view text, std::size_t open);

/// Parses and decodes every array; every fault is an InputError naming `file`.
void parse_vtu(const fs::path& file, std::string_view bytes, VtuDocument& out);

}  // namespace msfem::cases::detail
