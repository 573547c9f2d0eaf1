#pragma once

#include <cmath>
#include <ctime>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "msfem/cases/text.hpp"
#include "msfem/compare/commands/commands.hpp"

namespace msfem::compare {

/// Local time as YYYYmmdd-HHMMSS: the suffix of a run's default output folder.
inline std::string run_timestamp() {
  const std::time_t now = std::time(nullptr);
  char text[32];
  std::strftime(text, sizeof text, "%Y%m%d-%H%M%S", std::localtime(&now));
  return text;
}

/// Refuses an OUT that is IN itself (a command that rewrites a surface writes a new file; writing
/// over its input would lose it on a failure), naming the command.
inline void refuse_writing_over_input(const std::string& in, const std::string& out,
                                      const std::string& command) {
  std::error_code ignored;
  if (std::filesystem::weakly_canonical(in, ignored) ==
      std::filesystem::weakly_canonical(out, ignored))
    throw std::invalid_argument("OUT '" + out + "' is the input file: " + command +
                                " writes a new file");
}

/// Command-line options of one sub-command: `--flag`, `--key value` or `--key=value`, and
/// positional arguments. Anything not declared is an error naming the option, so a typo never goes
/// unnoticed.
class Options {
 public:
  Options(const Arguments& args, const std::set<std::string>& flags,
          const std::set<std::string>& valued) {
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      if (a.size() < 2 || a.rfind("--", 0) != 0) {
        positional_.push_back(a);
        continue;
      }
      std::string key = a.substr(2), value;
      const auto eq = key.find('=');
      const bool inline_value = eq != std::string::npos;
      if (inline_value) {
        value = key.substr(eq + 1);
        key.resize(eq);
      }
      if (flags.count(key) && !inline_value) {
        flags_.insert(key);
      } else if (valued.count(key)) {
        if (!inline_value) {
          if (i + 1 >= args.size())
            throw std::invalid_argument("option --" + key + " needs a value");
          value = args[++i];
        }
        // A second --out or --threads would silently win over the first: only --set and
        // --set-at repeat.
        if (values_.count(key) && key != "set" && key != "set-at")
          throw std::invalid_argument("option --" + key + " is given twice");
        values_[key].push_back(value);
      } else {
        throw std::invalid_argument("unknown option '" + a + "'");
      }
    }
  }

  const std::vector<std::string>& positional() const { return positional_; }
  bool flag(const std::string& key) const { return flags_.count(key) > 0; }
  /// The last value given for --key.
  std::optional<std::string> value(const std::string& key) const {
    const auto it = values_.find(key);
    if (it == values_.end()) return std::nullopt;
    return it->second.back();
  }
  /// Every value given for a repeatable option such as --set, in order.
  std::vector<std::string> values(const std::string& key) const {
    const auto it = values_.find(key);
    return it == values_.end() ? std::vector<std::string>{} : it->second;
  }

  /// The comma-separated entries of --key (none when it is not given).
  std::vector<std::string> list(const std::string& key) const {
    const auto v = value(key);
    return v ? cases::split_list(*v) : std::vector<std::string>{};
  }

  /// Integer value of --key, or `fallback`; an unparsable or out-of-range value names the option.
  long integer(const std::string& key, long fallback) const {
    const auto v = value(key);
    if (!v) return fallback;
    std::size_t used = 0;
    long result = 0;
    try {
      result = std::stol(*v, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != v->size() || v->empty())
      throw std::invalid_argument("option --" + key + ": '" + *v + "' is not an integer");
    return result;
  }

  /// As integer(), and refused (naming the option and the range) outside [least, greatest].
  long integer(const std::string& key, long fallback, long least, long greatest) const {
    const long result = integer(key, fallback);
    if (result < least || result > greatest)
      throw std::invalid_argument("option --" + key + " " + std::to_string(result) +
                                  " is outside [" + std::to_string(least) + ", " +
                                  std::to_string(greatest) + "]");
    return result;
  }

  /// The finite number given for --key, or `fallback`; refused outside (least, greatest].
  double number(const std::string& key, double fallback, double least, double greatest) const {
    const auto v = value(key);
    if (!v) return fallback;
    std::size_t used = 0;
    double result = 0;
    try {
      result = std::stod(*v, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != v->size() || v->empty() || !std::isfinite(result))
      throw std::invalid_argument("option --" + key + ": '" + *v + "' is not a number");
    if (!(result > least) || result > greatest)
      throw std::invalid_argument("option --" + key + " " + *v + " is outside (" +
                                  std::to_string(least) + ", " + std::to_string(greatest) + "]");
    return result;
  }

 private:
  std::vector<std::string> positional_;
  std::set<std::string> flags_;
  std::map<std::string, std::vector<std::string>> values_;
};

}  // namespace msfem::compare
