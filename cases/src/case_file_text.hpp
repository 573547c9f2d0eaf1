#pragma once
// A case file as text, checked before deal.II's ParameterHandler parses it: the checks its parser
// does not make (or makes by crashing).

#include <filesystem>
#include <set>
#include <string>

namespace msfem::cases {

/// Most nested `include`s a case file may have.
inline constexpr int max_include_depth = 8;

/// The case file's text, ready for ParameterHandler::parse_input. Throws InputError naming the file
/// (and line) for a directory, an unreadable or empty file, an `include` that is missing, includes
/// itself directly or through others, or nests deeper than max_include_depth, and for a key set
/// twice in one subsection (anywhere in the included files). A UTF-8 byte-order mark is dropped.
/// The case file's own `include` paths are made absolute against its folder, so they resolve
/// against the case file, as geometry/source does, not against the working directory.
/// `sections` lists the language's subsections as paths ("loads/tool"): a `subsection` line naming
/// another is refused there, naming the file, line and the known sections at that level (the
/// parser would blame the first key inside it instead).
std::string checked_case_text(const std::filesystem::path& file,
                              const std::set<std::string>& sections);

/// The same for `contents` given as the text of `file` (the file itself is not read; its includes
/// are): what the case reader's fuzz target drives.
std::string checked_case_text(const std::filesystem::path& file, const std::string& contents,
                              const std::set<std::string>& sections);

/// The subsection paths of a parameter file as ParameterHandler prints it ("a", "a/b", ...).
std::set<std::string> subsection_paths(const std::string& printed_parameters);

}  // namespace msfem::cases
