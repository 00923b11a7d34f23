#pragma once
/// The processes a long job runs on: one, or the ranks of an MPI job started by `mpirun`
/// or a Slurm step (docs/cluster.md). Work is shared as independent items through a dynamic
/// queue: every rank asks for the next item when it is free, and items are handed out in the
/// order given (largest first), so a slow item does not hold the end of the run.
///
/// The queue hands out indices only; what an item computes must depend on the item alone
/// (its seed from the run's seed and the item's identity), never on the rank that ran it or
/// on the order. Results travel through files the caller writes (atomically, on a folder
/// every rank sees) and, for small text, `gather`.
#include <cstddef>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/run_context.hpp"

namespace clumpforge {

/// How a process takes part in a team.
struct TeamOptions {
  /// Threads per rank for the work inside an item (0: the node's cores shared evenly among
  /// the ranks on that node, at least one each).
  int threads_per_rank = 0;
};

class Team {
 public:
  /// A team of one process (no MPI).
  Team();
  ~Team();
  Team(Team&&) noexcept;
  Team& operator=(Team&&) noexcept;
  Team(const Team&) = delete;
  Team& operator=(const Team&) = delete;

  /// Joins the MPI job this process was started in (mpirun, srun) and initialises MPI, or a
  /// team of one when the process was started on its own or the build has no MPI. At most
  /// one per process; MPI is finalised when it is destroyed.
  static Result<Team> join(const TeamOptions& options = {});

  int rank() const;
  int size() const;
  /// True when this process is one of several ranks of an MPI job.
  bool distributed() const { return size() > 1; }
  /// The rank that writes what is shared (reports, assembled outputs).
  bool leader() const { return rank() == 0; }
  /// Threads each rank uses for the work inside an item.
  int threads() const;
  /// "1 process" or "3 MPI ranks x 2 threads".
  std::string describe() const;

  /// Runs `work(i)` for every index of `order` across the ranks, handing out the next index to
  /// whichever rank is free, in `order`'s order. Every rank calls it with the same `order`.
  /// A rank whose work fails stops asking for more; the others finish the queue. `progress`
  /// (leader only) is told the number of items handed out so far. Returns this rank's first
  /// error, or a note that another rank failed (so every rank stops alike).
  Result<void> share(std::span<const std::size_t> order, const std::function<Result<void>(std::size_t)>& work,
                     const std::function<void(std::size_t handed_out, std::size_t total)>& progress = {}) const;

  /// `share` for work whose result is a few numbers: `work(i)` returns item i's `width` values,
  /// and every rank gets every item's values (indexed like `order`'s items, exact bits,
  /// whichever rank ran it). Every rank calls it with the same `order` and `width`.
  Result<std::vector<std::vector<double>>> map(
      std::span<const std::size_t> order, std::size_t width,
      const std::function<Result<std::vector<double>>(std::size_t)>& work,
      const std::function<void(std::size_t handed_out, std::size_t total)>& progress = {}) const;

  /// The leader's `text` on every rank (what the others pass is ignored): work done once, on the
  /// leader, and shared (a list of inputs and their digests).
  std::string broadcast(const std::string& text) const;
  /// Every rank's `line`, in rank order, on the leader (the others get an empty list).
  std::vector<std::string> gather(const std::string& line) const;
  /// The element-wise sum of every rank's `values` (the same length on every rank), on every
  /// rank: each rank fills the entries it computed and leaves the others zero.
  std::vector<double> sum(std::vector<double> values) const;
  /// True on every rank when `mine` is true on every rank.
  bool all(bool mine) const;
  /// Waits for every rank, without keeping a core busy while it waits.
  void wait_for_all() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

/// Whether this build can run on MPI (CLUMPFORGE_MPI).
bool team_has_mpi();

}  // namespace clumpforge
