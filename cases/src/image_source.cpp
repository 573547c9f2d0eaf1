// A case file names an image as its geometry: "image:FILE:label=N" or
// "image:FILE:threshold=LO[:HI]", so that one `msfem run` goes from the scan to the report.
#include <string>
#include <vector>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/surface_from_image.hpp"

namespace msfem::cases {
namespace {

constexpr const char* prefix = "image:";

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (std::size_t end; (end = text.find(separator, start)) != std::string::npos; start = end + 1)
    parts.push_back(text.substr(start, end - start));
  parts.push_back(text.substr(start));
  return parts;
}

[[noreturn]] void refuse(const std::string& source, const std::string& why) {
  throw InputError("geometry/source '" + source + "': " + why +
                   " (expected image:FILE:label=N or image:FILE:threshold=LO[:HI])");
}

long parse_label(const std::string& source, const std::string& text) {
  std::size_t used = 0;
  long label = 0;
  try {
    label = std::stol(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size()) refuse(source, "label '" + text + "' is not an integer");
  return label;
}

}  // namespace

bool is_image_source(const std::string& source) {
  return source.rfind(prefix, 0) == 0;
}

ImageSource parse_image_source(const std::string& source) {
  const auto parts = split(source.substr(std::string(prefix).size()), ':');
  if (parts[0].empty()) refuse(source, "no image file");
  ImageSource result{parts[0], {}};
  const std::string what = "geometry/source '" + source + "': threshold";
  bool selected = false;
  for (std::size_t i = 1; i < parts.size(); ++i) {
    if (selected) refuse(source, "'" + parts[i] + "' after the selection");
    selected = true;
    if (parts[i].rfind("label=", 0) == 0) {
      result.selection.label = parse_label(source, parts[i].substr(6));
    } else if (parts[i].rfind("threshold=", 0) == 0) {
      const bool has_high = i + 1 < parts.size();
      result.selection =
          parse_threshold(parts[i].substr(10) + (has_high ? ":" + parts[i + 1] : ""), what);
      i += has_high;
    } else {
      refuse(source, "'" + parts[i] + "' is neither label=N nor threshold=LO[:HI]");
    }
  }
  if (!selected) refuse(source, "no label=N or threshold=LO[:HI]");
  return result;
}

std::string image_source_relative_to(const std::string& source,
                                     const std::filesystem::path& folder) {
  const ImageSource parsed = parse_image_source(source);
  if (parsed.file.is_absolute()) return source;
  const std::string rest = source.substr(std::string(prefix).size() + parsed.file.string().size());
  return prefix + (folder / parsed.file).lexically_normal().string() + rest;
}

}  // namespace msfem::cases
