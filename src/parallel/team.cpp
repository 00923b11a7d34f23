#include "parallel/team.hpp"

#include <fmt/format.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <mutex>
#include <optional>
#include <thread>

#ifdef CLUMPFORGE_MPI
#include <mpi.h>
#endif

namespace clumpforge {

namespace {

constexpr int kAsk = 1, kAnswer = 2;
constexpr long long kNoMore = -1, kLeaving = -2;

/// Open MPI (mpirun), PMIx (srun, mpirun of Open MPI 4+), MPICH/Hydra and Slurm's PMI2 set
/// one of these in every rank's environment; a process started on its own has none.
bool started_by_a_launcher() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE", "PMI_RANK"})
    if (std::getenv(name) != nullptr) return true;
  return false;
}

int hardware_threads() {
  return std::max(1u, std::thread::hardware_concurrency());
}

}  // namespace

struct Team::Impl {
  int rank = 0, size = 1, threads = 1;
  bool mpi = false;
  std::optional<tbb::global_control> limit;
#ifdef CLUMPFORGE_MPI
  MPI_Comm world = MPI_COMM_NULL;
#endif
  ~Impl() {
    limit.reset();
#ifdef CLUMPFORGE_MPI
    if (mpi) {
      MPI_Comm_free(&world);
      MPI_Finalize();
    }
#endif
  }
};

Team::Team() : impl_(std::make_unique<Impl>()) {
  impl_->threads = hardware_threads();
}
Team::~Team() = default;
Team::Team(Team&&) noexcept = default;
Team& Team::operator=(Team&&) noexcept = default;

bool team_has_mpi() {
#ifdef CLUMPFORGE_MPI
  return true;
#else
  return false;
#endif
}

Result<Team> Team::join(const TeamOptions& options) {
  if (options.threads_per_rank < 0)
    return fail(ErrorCode::InvalidArgument,
                fmt::format("threads per rank must be 0 (automatic) or more, not {}", options.threads_per_rank));
  Team team;
  int local = 1;
#ifdef CLUMPFORGE_MPI
  if (started_by_a_launcher()) {
    int provided = 0;
    // Serialized: on the leader a queue thread answers the other ranks while the main thread
    // works; the two never call MPI at the same time.
    if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS)
      return fail(ErrorCode::IoError, "MPI could not be initialised");
    team.impl_->mpi = true;
    if (provided < MPI_THREAD_SERIALIZED) {
      MPI_Finalize();
      team.impl_->mpi = false;
      return fail(ErrorCode::IoError,
                  "this MPI library does not allow calls from a second thread (MPI_THREAD_SERIALIZED)");
    }
    MPI_Comm_dup(MPI_COMM_WORLD, &team.impl_->world);
    MPI_Comm_rank(team.impl_->world, &team.impl_->rank);
    MPI_Comm_size(team.impl_->world, &team.impl_->size);
    MPI_Comm node;
    MPI_Comm_split_type(team.impl_->world, MPI_COMM_TYPE_SHARED, team.impl_->rank, MPI_INFO_NULL, &node);
    MPI_Comm_size(node, &local);
    MPI_Comm_free(&node);
  }
#endif
  team.impl_->threads =
      options.threads_per_rank > 0 ? options.threads_per_rank : std::max(1, hardware_threads() / local);
  if (team.impl_->mpi || options.threads_per_rank > 0)
    team.impl_->limit.emplace(tbb::global_control::max_allowed_parallelism,
                              static_cast<std::size_t>(team.impl_->threads));
  return team;
}

int Team::rank() const {
  return impl_->rank;
}
int Team::size() const {
  return impl_->size;
}
int Team::threads() const {
  return impl_->threads;
}

std::string Team::describe() const {
  if (!impl_->mpi) return fmt::format("1 process x {} thread{}", impl_->threads, impl_->threads == 1 ? "" : "s");
  return fmt::format("{} MPI rank{} x {} thread{}", impl_->size, impl_->size == 1 ? "" : "s", impl_->threads,
                     impl_->threads == 1 ? "" : "s");
}

void Team::wait_for_all() const {
#ifdef CLUMPFORGE_MPI
  if (!impl_->mpi) return;
  // A blocking barrier spins; a rank that is done would take a core from one still working.
  MPI_Request request;
  MPI_Ibarrier(impl_->world, &request);
  int done = 0;
  while (MPI_Test(&request, &done, MPI_STATUS_IGNORE), !done) std::this_thread::sleep_for(std::chrono::milliseconds(2));
#endif
}

bool Team::all(bool mine) const {
#ifdef CLUMPFORGE_MPI
  if (!impl_->mpi) return mine;
  wait_for_all();
  int in = mine ? 1 : 0, out = 0;
  MPI_Allreduce(&in, &out, 1, MPI_INT, MPI_LAND, impl_->world);
  return out != 0;
#else
  return mine;
#endif
}

std::vector<double> Team::sum(std::vector<double> values) const {
#ifdef CLUMPFORGE_MPI
  if (impl_->mpi && impl_->size > 1) {
    wait_for_all();
    MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE, MPI_SUM, impl_->world);
  }
#endif
  return values;
}

Result<std::vector<std::vector<double>>> Team::map(
    std::span<const std::size_t> order, std::size_t width,
    const std::function<Result<std::vector<double>>(std::size_t)>& work,
    const std::function<void(std::size_t, std::size_t)>& progress) const {
  const std::size_t count = order.empty() ? 0 : *std::max_element(order.begin(), order.end()) + 1;
  std::vector<double> packed(count * width, 0.0);
  auto one = [&](std::size_t i) -> Result<void> {
    auto values = work(i);
    if (!values) return std::unexpected(values.error());
    if (values->size() != width)
      return fail(ErrorCode::InvalidArgument,
                  fmt::format("work item {} gave {} values where {} were expected", i, values->size(), width));
    std::copy(values->begin(), values->end(), packed.begin() + static_cast<std::ptrdiff_t>(i * width));
    return {};
  };
  auto shared = share(order, one, progress);
  // Each rank holds the items it ran and zeros elsewhere: the sum is every item, exactly.
  packed = sum(std::move(packed));
  if (!shared) return std::unexpected(shared.error());
  std::vector<std::vector<double>> out(count);
  for (std::size_t i = 0; i < count; ++i)
    out[i].assign(packed.begin() + static_cast<std::ptrdiff_t>(i * width),
                  packed.begin() + static_cast<std::ptrdiff_t>((i + 1) * width));
  return out;
}

std::string Team::broadcast(const std::string& text) const {
#ifdef CLUMPFORGE_MPI
  if (impl_->mpi && impl_->size > 1) {
    wait_for_all();
    unsigned long long length = leader() ? text.size() : 0;
    MPI_Bcast(&length, 1, MPI_UNSIGNED_LONG_LONG, 0, impl_->world);
    std::string out = leader() ? text : std::string(static_cast<std::size_t>(length), '\0');
    for (unsigned long long sent = 0; sent < length;) {  // in pieces below MPI's int count
      const int piece = static_cast<int>(std::min<unsigned long long>(length - sent, 1ULL << 30));
      MPI_Bcast(out.data() + sent, piece, MPI_CHAR, 0, impl_->world);
      sent += static_cast<unsigned long long>(piece);
    }
    return out;
  }
#endif
  return text;
}

std::vector<std::string> Team::gather(const std::string& line) const {
#ifdef CLUMPFORGE_MPI
  if (impl_->mpi) {
    wait_for_all();
    const int length = static_cast<int>(line.size());
    std::vector<int> lengths(static_cast<std::size_t>(impl_->size)), offsets(lengths.size());
    MPI_Gather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, 0, impl_->world);
    int total = 0;
    for (std::size_t r = 0; r < lengths.size(); ++r) {
      offsets[r] = total;
      total += lengths[r];
    }
    std::string joined(static_cast<std::size_t>(leader() ? total : 0), '\0');
    MPI_Gatherv(line.data(), length, MPI_CHAR, joined.data(), lengths.data(), offsets.data(), MPI_CHAR, 0,
                impl_->world);
    if (!leader()) return {};
    std::vector<std::string> out;
    for (std::size_t r = 0; r < lengths.size(); ++r)
      out.push_back(joined.substr(static_cast<std::size_t>(offsets[r]), static_cast<std::size_t>(lengths[r])));
    return out;
  }
#endif
  return {line};
}

namespace {

/// The queue's counter: on the leader, shared by its own work loop and, under MPI, the thread
/// that answers the other ranks.
struct Counter {
  std::mutex mutex;
  std::size_t next = 0, total = 0;
  std::optional<std::size_t> take() {
    std::lock_guard lock(mutex);
    if (next >= total) return std::nullopt;
    return next++;
  }
};

}  // namespace

Result<void> Team::share(std::span<const std::size_t> order, const std::function<Result<void>(std::size_t)>& work,
                         const std::function<void(std::size_t, std::size_t)>& progress) const {
  Counter counter;
  counter.total = order.size();
  std::optional<Error> failure;
#ifdef CLUMPFORGE_MPI
  std::thread server;
  std::atomic<bool> serving = impl_->mpi && impl_->size > 1 && leader();
  if (serving) {
    // Answers the other ranks' requests until each has been told there is no more (or left).
    server = std::thread([&] {
      int open = impl_->size - 1;
      while (open > 0) {
        int waiting = 0;
        MPI_Status status;
        MPI_Iprobe(MPI_ANY_SOURCE, kAsk, impl_->world, &waiting, &status);
        if (!waiting) {
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
          continue;
        }
        long long message = 0;
        MPI_Recv(&message, 1, MPI_LONG_LONG, status.MPI_SOURCE, kAsk, impl_->world, MPI_STATUS_IGNORE);
        if (message == kLeaving) {
          --open;
          continue;
        }
        const auto index = counter.take();
        const long long answer = index ? static_cast<long long>(*index) : kNoMore;
        MPI_Send(&answer, 1, MPI_LONG_LONG, status.MPI_SOURCE, kAnswer, impl_->world);
        if (!index) --open;
      }
    });
  }
  auto next = [&]() -> std::optional<std::size_t> {
    if (!impl_->mpi || impl_->size == 1 || leader()) return counter.take();
    const long long ask = 0;
    long long answer = kNoMore;
    MPI_Send(&ask, 1, MPI_LONG_LONG, 0, kAsk, impl_->world);
    MPI_Request request;
    MPI_Irecv(&answer, 1, MPI_LONG_LONG, 0, kAnswer, impl_->world, &request);
    int done = 0;
    while (MPI_Test(&request, &done, MPI_STATUS_IGNORE), !done)
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    if (answer < 0) return std::nullopt;
    return static_cast<std::size_t>(answer);
  };
#else
  auto next = [&]() { return counter.take(); };
#endif
  while (auto index = next()) {
    if (progress && leader()) {
      std::lock_guard lock(counter.mutex);
      progress(counter.next, counter.total);
    }
    if (auto ok = work(order[*index]); !ok) {
      failure = ok.error();
      break;
    }
  }
#ifdef CLUMPFORGE_MPI
  if (failure && impl_->mpi && impl_->size > 1 && !leader()) {
    const long long leaving = kLeaving;
    MPI_Send(&leaving, 1, MPI_LONG_LONG, 0, kAsk, impl_->world);
  }
  if (server.joinable()) {
    if (failure) {
      // The leader failed: hand out nothing more, but answer until every rank has heard so.
      std::lock_guard lock(counter.mutex);
      counter.next = counter.total;
    }
    server.join();
  }
#endif
  const auto lines = gather(failure ? failure->message : std::string());
  const bool ok = all(!failure);
  if (failure) return std::unexpected(*failure);
  if (ok) return {};
  for (std::size_t r = 0; r < lines.size(); ++r)
    if (!lines[r].empty()) return fail(ErrorCode::IoError, fmt::format("rank {}: {}", r, lines[r]));
  return fail(ErrorCode::IoError, "another rank failed (its message is in the leader's output)");
}

}  // namespace clumpforge
