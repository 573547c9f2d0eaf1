#include "msfem/compare/pipeline/atomic_file.hpp"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <fstream>
#include <memory>
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

// Temporaries in progress, removed if SIGINT, SIGTERM or SIGHUP ends the program, so an
// interrupted run leaves nothing behind. The handler may only make async-signal-safe calls: fork,
// execv and waitpid are, a recursive directory removal is not, hence rm in a child process.
constexpr int kMaxPending = 8;
char pending_paths[kMaxPending][4096];
volatile std::sig_atomic_t pending_used[kMaxPending] = {};

extern "C" void remove_pending_and_reraise(int signal_number) {
  for (int i = 0; i < kMaxPending; ++i) {
    if (!pending_used[i]) continue;
    const pid_t child = ::fork();
    if (child == 0) {
      char rm[] = "rm", flags[] = "-rf", end[] = "--";
      char* argv[] = {rm, flags, end, pending_paths[i], nullptr};
      ::execv("/bin/rm", argv);
      ::_exit(127);
    }
    if (child > 0) ::waitpid(child, nullptr, 0);
  }
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
}

void install_cleanup_handlers() {
  static bool installed = false;
  if (installed) return;
  installed = true;
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction current {};
    if (::sigaction(signal_number, nullptr, &current) != 0) continue;
    if (current.sa_handler != SIG_DFL) continue;  // the embedding program's own handler wins
    struct sigaction action {};
    action.sa_handler = remove_pending_and_reraise;
    sigemptyset(&action.sa_mask);
    ::sigaction(signal_number, &action, nullptr);
  }
}

// Registers a temporary for removal on a signal while it is alive.
class PendingTemporary {
 public:
  explicit PendingTemporary(const fs::path& path) {
    const std::string text = fs::absolute(path).string();
    if (text.size() >= sizeof pending_paths[0]) return;
    install_cleanup_handlers();
    for (int i = 0; i < kMaxPending; ++i)
      if (!pending_used[i]) {
        std::memcpy(pending_paths[i], text.c_str(), text.size() + 1);
        pending_used[i] = 1;
        slot_ = i;
        return;
      }
  }
  ~PendingTemporary() {
    if (slot_ >= 0) pending_used[slot_] = 0;
  }
  PendingTemporary(const PendingTemporary&) = delete;
  PendingTemporary& operator=(const PendingTemporary&) = delete;

 private:
  int slot_ = -1;
};

void remove_quietly(const fs::path& path) {
  std::error_code ignored;
  fs::remove(path, ignored);
}

// A claim on a result folder, DIR.lock holding the claiming process's id, taken before any work: a
// second run given the same --out is refused at once instead of computing for minutes and then
// failing on the rename. A claim whose process has died (killed without its handlers) is taken
// over.
class FolderClaim {
 public:
  explicit FolderClaim(const fs::path& directory)
      : path_(directory.parent_path() / (directory.filename().string() + ".lock")) {
    if (!directory.parent_path().empty()) {
      std::error_code ignored;
      fs::create_directories(directory.parent_path(), ignored);
    }
    for (int attempt = 0; attempt < 2; ++attempt) {
      const int fd = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
      if (fd >= 0) {
        const std::string pid = std::to_string(::getpid()) + "\n";
        const bool written = ::write(fd, pid.data(), pid.size()) == ssize_t(pid.size());
        ::close(fd);
        if (!written) break;
        pending_ = std::make_unique<PendingTemporary>(path_);
        return;
      }
      if (errno != EEXIST) break;
      long holder = 0;
      std::ifstream(path_) >> holder;
      if (holder > 0 && (::kill(pid_t(holder), 0) == 0 || errno == EPERM))
        throw cases::InputError(directory.string() + ": another msfem (process " +
                                std::to_string(holder) + ") is writing this output folder");
      remove_quietly(path_);
    }
    throw cases::InputError(directory.string() + ": cannot claim the output folder (" +
                            path_.string() + ": " + std::strerror(errno) + ")");
  }
  ~FolderClaim() {
    pending_.reset();
    remove_quietly(path_);
  }
  FolderClaim(const FolderClaim&) = delete;
  FolderClaim& operator=(const FolderClaim&) = delete;

 private:
  fs::path path_;
  std::unique_ptr<PendingTemporary> pending_;
};

}  // namespace

void write_file_atomically(const fs::path& path,
                           const std::function<void(const fs::path& temporary)>& write) {
  if (path.filename().empty())
    throw std::runtime_error("cannot write '" + path.string() + "': not a file name");
  const fs::path temporary = temporary_name_for(path);
  const PendingTemporary pending(temporary);
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

void check_output_folder(const fs::path& directory) {
  if (directory.empty()) throw cases::InputError("the output folder is an empty path");
  if (fs::exists(directory) && !(fs::is_directory(directory) && fs::is_empty(directory)))
    throw cases::InputError(directory.string() + ": output folder exists and is not empty");
}

void fill_directory_atomically(const fs::path& directory,
                               const std::function<void(const fs::path& work)>& fill) {
  check_output_folder(directory);
  const FolderClaim claim(directory);
  check_output_folder(directory);  // a run that finished while this one claimed
  const fs::path work = temporary_name_for(directory);
  const PendingTemporary pending(work);
  std::error_code created;
  fs::create_directories(work, created);
  if (created)
    throw cases::InputError(directory.string() + ": cannot create the output folder there (" +
                            created.message() + ")");
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

fs::path fem_cache_beside(const fs::path& run_folder) {
  const fs::path parent = run_folder.has_parent_path() ? run_folder.parent_path() : fs::path(".");
  const fs::path cache = parent / ".fem-cache";
  std::error_code failed;
  fs::create_directories(cache, failed);
  if (failed || access(cache.c_str(), W_OK) != 0)
    throw cases::InputError(cache.string() + ": cannot write the FEM cache there (" +
                            (failed ? failed.message() : std::string("not writable")) +
                            "); give --no-cache or an --out in a writable folder");
  return cache;
}

}  // namespace msfem::compare
