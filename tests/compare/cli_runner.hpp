#pragma once
// Runs the msfem program and captures what a user would see.

#include <sys/wait.h>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

namespace msfem::testing {

/// The small sphere case the run, sweep and modulus-image tests share (tests/compare/data).
inline const std::string small_sphere_case = std::string(MSFEM_TEST_DATA_DIR) + "/small_sphere.prm";

struct CommandResult {
  int exit_code = -1;
  std::string out, err;
};

inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A fresh folder under the system's temporary directory, removed with the object.
class TemporaryDirectory {
 public:
  TemporaryDirectory() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() / ("msfem_cli_" + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TemporaryDirectory() { std::filesystem::remove_all(path_); }
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

/// `msfem ARGS` through the shell, stdout and stderr kept apart.
inline CommandResult run_msfem(const std::string& args) {
  TemporaryDirectory tmp;
  const auto out = tmp / "out.txt", err = tmp / "err.txt";
  const std::string cmd =
      std::string(MSFEM_EXECUTABLE) + " " + args + " >" + out.string() + " 2>" + err.string();
  const int status = std::system(cmd.c_str());
  CommandResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = read_text(out);
  r.err = read_text(err);
  return r;
}

inline std::size_t count_lines(const std::string& s) {
  std::size_t n = 0;
  for (char c : s)
    n += c == '\n';
  return n;
}

}  // namespace msfem::testing
