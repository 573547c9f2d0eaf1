#include "msfem/compare/pipeline/ranks.hpp"

#include <fcntl.h>
#include <mpi.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <thread>

#include "msfem/cases/errors.hpp"

namespace msfem::compare::ranks {
namespace {

bool started_here = false;
int saved_stderr = -1;  // rank > 0: the job's stderr, for a failure only that rank saw
// The exit-code agreement's own communicator: a rank that arrives there while another is still in
// a collective of the run must not be matched with that collective.
MPI_Comm agreement = MPI_COMM_NULL;

bool running() {
  int initialised = 0, finalised = 0;
  MPI_Initialized(&initialised);
  MPI_Finalized(&finalised);
  return initialised && !finalised;
}

bool launched() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(name)) return true;
  return false;
}

void silence_output() {
  saved_stderr = dup(STDERR_FILENO);
  const int null = open("/dev/null", O_WRONLY);
  if (null < 0) return;
  std::fflush(stdout);
  std::fflush(stderr);
  dup2(null, STDOUT_FILENO);
  dup2(null, STDERR_FILENO);
  close(null);
}

// Polls `request` with short sleeps; false if `limit_s` (> 0) passed first.
bool wait_idle(MPI_Request& request, double limit_s) {
  const auto start = std::chrono::steady_clock::now();
  for (;;) {
    int done = 0;
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done) return true;
    if (limit_s > 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > limit_s)
      return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

void write_saved(const std::string& line) {
  if (saved_stderr < 0) return;
  const std::string text = line + "\n";
  if (write(saved_stderr, text.data(), text.size()) < 0) return;
}

std::vector<std::string> all_gather(const std::string& bytes) {
  const int n = count();
  int size = static_cast<int>(bytes.size());
  std::vector<int> sizes(n), offsets(n, 0);
  MPI_Allgather(&size, 1, MPI_INT, sizes.data(), 1, MPI_INT, MPI_COMM_WORLD);
  for (int r = 1; r < n; ++r)
    offsets[r] = offsets[r - 1] + sizes[r - 1];
  std::string all(static_cast<std::size_t>(offsets.back() + sizes.back()), '\0');
  MPI_Allgatherv(bytes.data(), size, MPI_CHAR, all.data(), sizes.data(), offsets.data(), MPI_CHAR,
                 MPI_COMM_WORLD);
  std::vector<std::string> parts(n);
  for (int r = 0; r < n; ++r)
    parts[r] = all.substr(static_cast<std::size_t>(offsets[r]), static_cast<std::size_t>(sizes[r]));
  return parts;
}

[[noreturn]] void throw_as(char kind, const std::string& message) {
  if (kind == 'i') throw cases::InputError(message);
  if (kind == 'a') throw std::invalid_argument(message);
  throw std::runtime_error(message);
}

}  // namespace

int count() {
  if (!running()) return 1;
  int n = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}

int index() {
  if (!running()) return 0;
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

std::vector<int> deal(const std::vector<double>& cost, int ranks) {
  std::vector<std::size_t> order(cost.size());
  for (std::size_t j = 0; j < order.size(); ++j)
    order[j] = j;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return cost[a] > cost[b]; });
  std::vector<double> work(static_cast<std::size_t>(std::max(ranks, 1)), 0.0);
  std::vector<int> owner(cost.size(), 0);
  for (const std::size_t j : order) {
    const auto least = std::min_element(work.begin(), work.end());
    owner[j] = static_cast<int>(least - work.begin());
    *least += cost[j];
  }
  return owner;
}

int on_this_machine() {
  if (count() == 1) return 1;
  static const int ranks = [] {
    MPI_Comm machine = MPI_COMM_NULL;
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &machine);
    int n = 1;
    MPI_Comm_size(machine, &n);
    MPI_Comm_free(&machine);
    return n;
  }();
  return ranks;
}

void start_if_launched() {
  if (!launched() || running()) return;
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
  started_here = true;
  MPI_Comm_dup(MPI_COMM_WORLD, &agreement);
  if (count() > 1 && index() != 0) silence_output();
}

int finish(int code, const std::string& failure) {
  if (!started_here) return code;
  if (count() > 1) {
    std::vector<int> codes(static_cast<std::size_t>(count()), 0);
    MPI_Request request;
    MPI_Iallgather(&code, 1, MPI_INT, codes.data(), 1, MPI_INT, agreement, &request);
    if (!wait_idle(request, code != 0 ? 60.0 : 0.0)) {
      const std::string why = "msfem (rank " + std::to_string(index()) + "): " + failure +
                              "; the other ranks did not follow: aborting the job";
      if (index() == 0) std::fprintf(stderr, "%s\n", why.c_str());
      write_saved(why);
      MPI_Abort(MPI_COMM_WORLD, code);
    }
    if (index() != 0 && codes.front() == 0 && code != 0 && !failure.empty())
      write_saved("msfem (rank " + std::to_string(index()) + "): " + failure);
    code = *std::max_element(codes.begin(), codes.end());
  }
  MPI_Comm_free(&agreement);
  MPI_Finalize();
  return code;
}

void agree(const std::function<void()>& work) {
  if (count() == 1) return work();
  char kind = 0;
  std::string message;
  try {
    work();
  } catch (const cases::InputError& e) {
    kind = 'i', message = e.what();
  } catch (const std::invalid_argument& e) {
    kind = 'a', message = e.what();
  } catch (const std::exception& e) {
    kind = 'r', message = e.what();
  } catch (...) {
    kind = 'r', message = "an unknown error";
  }
  idle_barrier();
  for (const std::string& part : all_gather(kind ? kind + message : std::string()))
    if (!part.empty()) throw_as(part.front(), part.substr(1));
}

std::vector<std::string> gather_on_all(const std::string& bytes) {
  if (count() == 1) return {bytes};
  idle_barrier();
  return all_gather(bytes);
}

std::string broadcast_from_root(const std::string& bytes) {
  if (count() == 1) return bytes;
  unsigned long long size = bytes.size();
  MPI_Bcast(&size, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD);
  std::string result = index() == 0 ? bytes : std::string(size, '\0');
  MPI_Bcast(result.data(), static_cast<int>(size), MPI_CHAR, 0, MPI_COMM_WORLD);
  return result;
}

bool on_every_rank(bool value) {
  if (count() == 1) return value;
  int mine = value ? 1 : 0, all = 0;
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  return all == 1;
}

void idle_barrier() {
  if (count() == 1) return;
  MPI_Request request;
  MPI_Ibarrier(MPI_COMM_WORLD, &request);
  wait_idle(request, 0.0);
}

}  // namespace msfem::compare::ranks
