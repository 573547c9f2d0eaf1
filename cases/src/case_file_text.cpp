#include "case_file_text.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/text.hpp"

namespace msfem::cases {
namespace {

namespace fs = std::filesystem;

// The words of a line with its comment removed and runs of blanks collapsed, as ParameterHandler
// reads names ("set  youngs   modulus" is the key "youngs modulus").
std::string normalised(std::string line) {
  const auto hash = line.find('#');
  if (hash != std::string::npos) line.resize(hash);
  std::string out;
  bool blank = false;
  for (char c : trimmed(line)) {
    const bool space = c == ' ' || c == '\t';
    if (space && blank) continue;
    out += space ? ' ' : c;
    blank = space;
  }
  return out;
}

bool starts_with_word(const std::string& line, const std::string& word) {
  if (line.size() < word.size()) return false;
  for (std::size_t i = 0; i < word.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(line[i])) != word[i]) return false;
  return line.size() == word.size() || line[word.size()] == ' ';
}

std::string without_byte_order_mark(std::string text, const fs::path& file,
                                    const std::string& where) {
  if (text.rfind("\xEF\xBB\xBF", 0) == 0) text.erase(0, 3);
  if (trimmed(text).empty()) throw InputError(where + file.string() + ": the case file is empty");
  return text;
}

std::string file_text(const fs::path& file, const std::string& where) {
  std::error_code ec;
  if (fs::is_directory(file, ec))
    throw InputError(where + file.string() + ": is a directory, not a case file");
  // A device or a pipe (an include of /dev/zero) would be read forever.
  if (fs::exists(file, ec) && !fs::is_regular_file(file, ec))
    throw InputError(where + file.string() + ": is not a regular file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(where + file.string() + ": cannot open case file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return without_byte_order_mark(buffer.str(), file, where);
}

// One file's lines (continuations joined as ParameterHandler joins them), with their numbers.
std::vector<std::pair<int, std::string>> logical_lines(const std::string& text) {
  std::vector<std::pair<int, std::string>> lines;
  std::istringstream in(text);
  std::string line, joined;
  int number = 0, first = 0;
  while (std::getline(in, line)) {
    ++number;
    if (joined.empty()) first = number;
    const std::string t = trimmed(line);
    if (!t.empty() && t.back() == '\\') {
      joined += t.substr(0, t.size() - 1);
      continue;
    }
    lines.emplace_back(first, joined + line);
    joined.clear();
  }
  if (!joined.empty()) lines.emplace_back(first, joined);
  return lines;
}

struct Scan {
  const std::set<std::string>* known = nullptr;  // the language's subsection paths
  std::vector<fs::path> stack;                   // the include chain, outermost first
  std::map<std::string, std::string> set_at;     // "section/.../key" -> "file:line"
  std::vector<std::string> sections;             // the subsection path at this point
};

std::string section_key(const std::vector<std::string>& sections, const std::string& key) {
  std::string path;
  for (const auto& s : sections)
    path += s + "/";
  return path + key;
}

void scan_file(const fs::path& file, const std::string& text, Scan& scan);

std::string joined(const std::vector<std::string>& sections) {
  std::string path;
  for (const auto& s : sections)
    path += (path.empty() ? "" : "/") + s;
  return path;
}

void check_section(const Scan& scan, const std::string& where) {
  const std::string path = joined(scan.sections);
  if (scan.sections.empty() || scan.known->count(path)) return;
  const std::vector<std::string> parent(scan.sections.begin(), scan.sections.end() - 1);
  const std::string prefix = parent.empty() ? "" : joined(parent) + "/";
  std::string known;
  for (const auto& s : *scan.known)
    if (s.rfind(prefix, 0) == 0 && s.find('/', prefix.size()) == std::string::npos)
      known += (known.empty() ? "" : ", ") + s.substr(prefix.size());
  throw InputError(where + "unknown subsection '" + path + "' (" +
                   (parent.empty() ? "sections" : "subsections of " + joined(parent)) + ": " +
                   known + ")");
}

void scan_include(const fs::path& included, const std::string& where, Scan& scan) {
  const fs::path canonical = fs::weakly_canonical(included);
  for (const auto& open : scan.stack)
    if (open == canonical)
      throw InputError(where + "include " + included.string() +
                       ": the file includes itself (directly or through other includes)");
  if (static_cast<int>(scan.stack.size()) > max_include_depth)
    throw InputError(where + "include " + included.string() + ": nested more than " +
                     std::to_string(max_include_depth) + " deep");
  scan_file(canonical, file_text(included, where), scan);
}

void scan_file(const fs::path& file, const std::string& text, Scan& scan) {
  scan.stack.push_back(fs::weakly_canonical(file));
  for (const auto& [number, raw] : logical_lines(text)) {
    const std::string line = normalised(raw);
    const std::string where = file.string() + ":" + std::to_string(number) + ": ";
    if (starts_with_word(line, "subsection")) {
      scan.sections.push_back(trimmed(line.substr(10)));
      check_section(scan, where);
    } else if (starts_with_word(line, "end")) {
      if (!scan.sections.empty()) scan.sections.pop_back();  // deal.II reports the imbalance
    } else if (starts_with_word(line, "include")) {
      scan_include(trimmed(line.substr(7)), where, scan);
    } else if (starts_with_word(line, "set")) {
      const auto eq = line.find('=');
      const std::string key = trimmed(line.substr(3, eq == std::string::npos ? eq : eq - 3));
      const std::string full = section_key(scan.sections, key);
      const auto [it, added] = scan.set_at.emplace(full, where.substr(0, where.size() - 2));
      if (!added)
        throw InputError(where + "'" + full + "' is set twice (first at " + it->second +
                         "): which value is meant?");
    }
  }
  scan.stack.pop_back();
}

// The case file's own include lines with their paths made absolute against its folder.
std::string with_absolute_includes(const fs::path& file, const std::string& text) {
  std::istringstream in(text);
  std::ostringstream out;
  for (std::string line; std::getline(in, line);) {
    const std::string t = normalised(line);
    if (starts_with_word(t, "include")) {
      const fs::path p = trimmed(t.substr(7));
      if (p.is_relative()) line = "include " + (file.parent_path() / p).lexically_normal().string();
    }
    out << line << '\n';
  }
  return out.str();
}

}  // namespace

std::set<std::string> subsection_paths(const std::string& printed_parameters) {
  std::set<std::string> paths;
  std::vector<std::string> stack;
  std::istringstream in(printed_parameters);
  for (std::string raw; std::getline(in, raw);) {
    const std::string line = normalised(raw);
    if (starts_with_word(line, "subsection")) {
      stack.push_back(trimmed(line.substr(10)));
      paths.insert(joined(stack));
    } else if (starts_with_word(line, "end") && !stack.empty()) {
      stack.pop_back();
    }
  }
  return paths;
}

std::string checked_case_text(const fs::path& file, const std::set<std::string>& sections) {
  return checked_case_text(file, file_text(file, ""), sections);
}

std::string checked_case_text(const fs::path& file, const std::string& contents,
                              const std::set<std::string>& sections) {
  const std::string text =
      with_absolute_includes(file, without_byte_order_mark(contents, file, ""));
  Scan scan;
  scan.known = &sections;
  scan_file(file, text, scan);
  return text;
}

}  // namespace msfem::cases
