#pragma once
// Text put into the XML msfem writes (VTK XML, X3D): one escaping for every writer.

#include <string>

namespace msfem::cases {

/// Text with &, <, >, " and ' escaped, for an XML attribute value or element text.
std::string xml_escaped(const std::string& text);

}  // namespace msfem::cases
