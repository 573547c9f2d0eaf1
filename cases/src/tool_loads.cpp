// Calibration tool loads, "DX,DY,DZ@DEPTH; ...": the case file's calibration section and
// msfem calibrate's --train and --test share this one reader.
#include <cmath>
#include <sstream>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/cases/errors.hpp"
#include "msfem/cases/text.hpp"

namespace msfem::cases {
namespace {

// Splits at `separator`, trimming each piece; a trailing empty piece is dropped ("a; b;").
std::vector<std::string> pieces(const std::string& text, char separator) {
  std::vector<std::string> out;
  std::string piece;
  std::istringstream in(text);
  while (std::getline(in, piece, separator))
    out.push_back(trimmed(piece));
  if (!out.empty() && out.back().empty()) out.pop_back();
  return out;
}

// A whole number text (nothing after it), finite.
double number(const std::string& text) {
  std::size_t used = 0;
  const double x = std::stod(text, &used);
  if (used != text.size() || !std::isfinite(x)) throw InputError("not a number");
  return x;
}

ToolLoad tool_load(const std::string& entry) {
  const auto at = entry.find('@');
  if (at == std::string::npos) throw InputError("no '@'");
  const std::vector<std::string> d = pieces(entry.substr(0, at), ',');
  if (d.size() != 3) throw InputError("not three components");
  ToolLoad load;
  load.direction = Eigen::Vector3d(number(d[0]), number(d[1]), number(d[2]));
  if (!(load.direction.norm() > 0)) throw InputError("zero direction");
  load.direction.normalize();
  load.depth_m = number(trimmed(entry.substr(at + 1)));
  if (!(load.depth_m > 0)) throw InputError("depth not > 0");
  return load;
}

}  // namespace

std::string ToolLoad::label() const {
  std::ostringstream out;
  out << direction.x() << ',' << direction.y() << ',' << direction.z() << '@' << depth_m;
  return out.str();
}

bool ToolLoad::same_as(const ToolLoad& other) const {
  return (direction - other.direction).norm() < 1e-9 && std::abs(depth_m - other.depth_m) < 1e-12;
}

std::vector<ToolLoad> parse_tool_loads(const std::string& text, const std::string& key) {
  std::vector<ToolLoad> loads;
  for (const std::string& entry : pieces(text, ';')) {
    try {
      loads.push_back(tool_load(entry));
    } catch (const std::exception&) {
      throw InputError(key + ": '" + entry +
                       "' is not DX,DY,DZ@DEPTH with a non-zero direction and a depth > 0 (m)");
    }
  }
  return loads;
}

}  // namespace msfem::cases
