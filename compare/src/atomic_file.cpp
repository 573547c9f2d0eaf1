#include "msfem/compare/atomic_file.hpp"

#include <unistd.h>

#include <fstream>
#include <stdexcept>
#include <system_error>

#include "msfem/cases/errors.hpp"

namespace msfem::compare {

namespace fs = std::filesystem;

namespace {

// The process id keeps two runs writing the same result folder from sharing a temporary.
fs::path temporary_name_for(const fs::path& path) {
  return path.parent_path() / (path.filename().string() + ".tmp." + std::to_string(::getpid()));
}

void remove_quietly(const fs::path& path) {
  std::error_code ignored;
  fs::remove(path, ignored);
}

}  // namespace

void write_file_atomically(const fs::path& path,
                           const std::function<void(const fs::path& temporary)>& write) {
  if (path.filename().empty())
    throw std::runtime_error("cannot write '" + path.string() + "': not a file name");
  const fs::path temporary = temporary_name_for(path);
  try {
    write(temporary);
    if (!fs::is_regular_file(temporary)) throw std::runtime_error("the writer produced no file");
    fs::rename(temporary, path);  // POSIX rename: readers see the old file or the new, never half
  } catch (const std::exception& e) {
    remove_quietly(temporary);
    throw std::runtime_error("cannot write '" + path.string() + "': " + e.what());
  } catch (...) {
    remove_quietly(temporary);
    throw;
  }
}

void write_text_atomically(const fs::path& path, const std::string& text) {
  write_file_atomically(path, [&text](const fs::path& temporary) {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot open '" + temporary.string() + "' for writing");
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();  // close() flushes: a full disk shows up here, not after the rename
    if (!out) throw std::runtime_error("writing '" + temporary.string() + "' failed");
  });
}

void fill_directory_atomically(const fs::path& directory,
                               const std::function<void(const fs::path& work)>& fill) {
  if (fs::exists(directory) && !(fs::is_directory(directory) && fs::is_empty(directory)))
    throw cases::InputError(directory.string() + ": output folder exists and is not empty");
  const fs::path work = temporary_name_for(directory);
  fs::create_directories(work);
  try {
    fill(work);
    std::error_code ignored;
    fs::remove(directory, ignored);  // an empty folder given with --out
    if (directory.has_parent_path()) fs::create_directories(directory.parent_path());
    fs::rename(work, directory);
  } catch (...) {
    std::error_code ignored;
    fs::remove_all(work, ignored);
    throw;  // as it was: bad input stays bad input
  }
}

}  // namespace msfem::compare
