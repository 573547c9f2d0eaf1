#pragma once
// msfem under mpirun or srun: every rank runs the same command; the FEM solves on all of them
// together, the independent work (spring variants at each load) is shared out, and rank 0 gathers,
// prints and writes. Without a launcher MPI is left alone (the FEM starts it for itself), and every
// function here sees one rank.

#include <functional>
#include <string>
#include <vector>

namespace msfem::compare::ranks {

/// Ranks in the job: 1 when MPI is not running.
int count();
/// This process's rank: 0 when MPI is not running.
int index();
inline bool is_root() {
  return index() == 0;
}
/// Ranks of the job on this rank's machine (sharing its cores): 1 when MPI is not running.
int on_this_machine();

/// Which of `ranks` ranks does each of a list of independent items, from each item's estimated
/// cost: the costliest first, each to the rank with the least work so far (longest processing
/// time first, within 4/3 of the best split; ties to the lower rank, so every rank deals alike).
/// Round-robin would give one rank every costly item where the costs repeat with a period of the
/// rank count.
std::vector<int> deal(const std::vector<double>& cost, int ranks = count());

/// Called first by `msfem`: starts MPI when a launcher (mpirun, srun) started the process with
/// more than one rank in mind, and sends the standard output and error of every rank but 0 to
/// /dev/null so that a job prints one progress stream and one result.
void start_if_launched();

/// Called last by `msfem` with the command's exit code and, if it failed, the line it printed:
/// the ranks agree on one exit code (the largest), a failure seen on a rank other than 0 alone is
/// printed there, and MPI is finalised if start_if_launched started it. A failed rank that cannot
/// reach the others within a minute (they are stuck in a collective it left) aborts the job with
/// its code rather than hang it.
int finish(int code, const std::string& failure);

/// Runs `work` on every rank. When it throws on any rank, every rank throws the failure of the
/// lowest such rank: a cases::InputError or std::invalid_argument as the same type (exit 2),
/// anything else as std::runtime_error, with the same message. On one rank it just runs `work`.
void agree(const std::function<void()>& work);

/// Every rank's `bytes` on every rank, in rank order.
std::vector<std::string> gather_on_all(const std::string& bytes);

/// Rank 0's `bytes` on every rank.
std::string broadcast_from_root(const std::string& bytes);

/// Whether `value` is true on every rank.
bool on_every_rank(bool value);

/// Returns when every rank has called it. A waiting rank sleeps rather than polls at full speed,
/// so that it leaves its core to a rank measuring steps per second.
void idle_barrier();

}  // namespace msfem::compare::ranks
