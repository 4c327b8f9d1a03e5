#include "src/render/stream/mpi_ray_exchange.h"

#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <utility>

#include "src/core/progress.h"
#include "src/render/stream/mpi_runtime.h"
#include "src/render/stream/mpi_wait.h"
#include "src/render/stream/ray_message.h"

namespace nave::render {

namespace {

// The tags of ray messages and of progress reports on the exchange's own communicator.
constexpr int kRaysTag = 1;
constexpr int kProgressTag = 2;
// Least time between two progress reports of a rank: the bar redraws about as often.
constexpr double kProgressReportSeconds = 0.5;

double SecondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Whether every slot's owner is one of the `ranks` ranks or kEveryRank; the error names the first
// that is not.
Status CheckOwners(const std::vector<int>& owners, int ranks) {
    for (size_t s = 0; s < owners.size(); ++s) {
        if ((owners[s] < 0 || owners[s] >= ranks) && owners[s] != kEveryRank) {
            return InvalidArgumentError(
                "ray exchange: brick slot {} owned by rank {} (expected [0, {}) or {}, every rank)",
                s, owners[s], ranks, kEveryRank);
        }
    }
    return Status::Ok();
}

}  // namespace

struct MpiRayExchange::Impl {
    Impl(std::vector<int> owners_in, BrickQueues<RayRecord>& queues_in,
         const MpiExchangeOptions& options_in)
        : owners(std::move(owners_in)), queues(queues_in), options(options_in) {}

    // A message ready to go, with the rays it holds.
    struct Message {
        std::vector<std::byte> bytes;
        uint64_t rays = 0;
    };
    // What workers append to for one destination rank (Send, under the mutex).
    struct Outgoing {
        std::mutex mutex;
        RayMessage filling;
        std::deque<Message> ready;
    };
    // A send posted and not yet complete: its buffer must live until then.
    struct Posted {
        MPI_Request request = MPI_REQUEST_NULL;
        std::vector<std::byte> bytes;
    };

    // Posts the full messages (and, with `all`, the partly filled ones too).
    Status PostReady(bool all);
    // Completes the finished sends of `list` (to one rank, or the progress reports); returns
    // whether any completed.
    StatusOr<bool> CompleteSends(std::deque<Posted>& list);
    // Receives and queues every message that has arrived; returns whether any did.
    StatusOr<bool> Receive();
    // Completes the receipt of a probed message of `bytes` from `source` into receive_buffer,
    // within the stall timeout.
    Status ReceiveMatched(MPI_Message* matched, int bytes, int source);
    // One step of progress with nothing else to do: sends and receipts.
    StatusOr<bool> Step();
    // Progress reports: a rank other than 0 sends what its bar gained since its last report (at
    // once with `now`, else after kProgressReportSeconds), and completes the reports sent; rank 0
    // adds the reports that have arrived to its bar.
    Status Report(bool now);
    Status ReceiveReports();
    // Receives one report from `source` (MPI_ANY_SOURCE: any rank) and adds it to the bar.
    Status TakeReport(int source);

    MPI_Comm rays_comm = MPI_COMM_NULL;  // point-to-point ray messages
    MPI_Comm sum_comm = MPI_COMM_NULL;   // the termination rounds' sums
    int rank = 0, size = 1;
    std::vector<int> owners;  // SetOwners replaces them between drains
    BrickQueues<RayRecord>& queues;
    const MpiExchangeOptions options;
    std::vector<std::unique_ptr<Outgoing>> outgoing;  // per rank
    std::vector<std::deque<Posted>> posted;           // per rank; the exchange's thread only
    ExchangeCounts counts;                            // the exchange's thread only
    // The sums of the last termination round, while a drain's end is being detected.
    uint64_t last_sums[2] = {0, 0};
    bool have_last_sums = false;
    std::vector<std::byte> receive_buffer;
    std::vector<std::byte> unpacked;  ///< a packed message's raw bytes (UnpackRayMessage)
    // Progress sharing (ShareProgress); the exchange's thread only.
    ProgressBar* bar = nullptr;
    uint64_t reported = 0;  // the bar's count at the last report
    std::chrono::steady_clock::time_point last_report;
    std::deque<Posted> reports;  // sent, not yet complete
    uint64_t reports_sent = 0, reports_received = 0;
};

StatusOr<std::unique_ptr<MpiRayExchange>> MpiRayExchange::Create(
    std::vector<int> owners, BrickQueues<RayRecord>& queues, const MpiExchangeOptions& options) {
    int initialized = 0;
    MPI_Initialized(&initialized);
    if (!initialized) return InternalError("MPI: the ray exchange needs MPI initialized first");
    if (owners.size() != queues.brick_count()) {
        return InvalidArgumentError("ray exchange: {} owners for {} brick slots", owners.size(),
                                    queues.brick_count());
    }
    if (options.message_bytes < kRayMessageHeaderBytes + kRayGroupHeaderBytes + sizeof(RayRecord) ||
        options.max_sends_in_flight < 1) {
        return InvalidArgumentError(
            "ray exchange: messages of {} bytes (expected room for one ray at least) or {} "
            "sends in flight (expected >= 1)",
            options.message_bytes, options.max_sends_in_flight);
    }
    auto impl = std::make_unique<Impl>(std::move(owners), queues, options);
    NAVE_RETURN_IF_ERROR(MpiStatus(MPI_Comm_dup(MPI_COMM_WORLD, &impl->rays_comm), "MPI_Comm_dup"));
    NAVE_RETURN_IF_ERROR(MpiStatus(MPI_Comm_dup(MPI_COMM_WORLD, &impl->sum_comm), "MPI_Comm_dup"));
    // Errors come back as codes, turned into Status here, instead of ending the process mute.
    MPI_Comm_set_errhandler(impl->rays_comm, MPI_ERRORS_RETURN);
    MPI_Comm_set_errhandler(impl->sum_comm, MPI_ERRORS_RETURN);
    MPI_Comm_rank(impl->rays_comm, &impl->rank);
    MPI_Comm_size(impl->rays_comm, &impl->size);
    NAVE_RETURN_IF_ERROR(CheckOwners(impl->owners, impl->size));
    impl->outgoing.resize(size_t(impl->size));
    for (auto& o : impl->outgoing) o = std::make_unique<Impl::Outgoing>();
    impl->posted.resize(size_t(impl->size));
    return std::unique_ptr<MpiRayExchange>(new MpiRayExchange(std::move(impl)));
}

MpiRayExchange::MpiRayExchange(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

MpiRayExchange::~MpiRayExchange() {
    // Sends still posted (a render that failed) are cancelled: their buffers go with the exchange.
    for (auto& dest : impl_->posted) {
        for (Impl::Posted& p : dest) {
            MPI_Cancel(&p.request);
            MPI_Request_free(&p.request);
        }
    }
    for (Impl::Posted& p : impl_->reports) {
        MPI_Cancel(&p.request);
        MPI_Request_free(&p.request);
    }
    MPI_Comm_free(&impl_->rays_comm);
    MPI_Comm_free(&impl_->sum_comm);
}

int MpiRayExchange::rank() const { return impl_->rank; }
int MpiRayExchange::size() const { return impl_->size; }
int MpiRayExchange::Owner(uint32_t slot) const { return impl_->owners[slot]; }

void MpiRayExchange::Send(uint32_t slot, std::span<const RayRecord> rays) {
    const int owner = impl_->owners[slot];
    SendToRank(TracedBy(owner, impl_->rank) ? impl_->rank : owner, slot, rays);
}

void MpiRayExchange::SendToRank(int dest, uint32_t slot, std::span<const RayRecord> rays) {
    if (dest == impl_->rank) {
        impl_->queues.Push(slot, rays.data(), rays.size());
        return;
    }
    Impl::Outgoing& out = *impl_->outgoing[size_t(dest)];
    const size_t per_message =
        (impl_->options.message_bytes - kRayMessageHeaderBytes - kRayGroupHeaderBytes) /
        sizeof(RayRecord);
    std::lock_guard<std::mutex> lock(out.mutex);
    while (!rays.empty()) {
        const size_t room =
            per_message > out.filling.ray_count() ? per_message - out.filling.ray_count() : 0;
        const size_t n = std::min(rays.size(), std::max<size_t>(room, 1));
        out.filling.Append(slot, rays.first(n));
        rays = rays.subspan(n);
        if (out.filling.size_bytes() + kRayGroupHeaderBytes + sizeof(RayRecord) >
            impl_->options.message_bytes) {
            const uint64_t count = out.filling.ray_count();
            out.ready.push_back({out.filling.Take(), count});
        }
    }
}

Status MpiRayExchange::Impl::PostReady(bool all) {
    for (int dest = 0; dest < size; ++dest) {
        if (dest == rank) continue;
        std::deque<Message> ready;
        {
            Outgoing& out = *outgoing[size_t(dest)];
            std::lock_guard<std::mutex> lock(out.mutex);
            if (all && !out.filling.empty()) {
                const uint64_t count = out.filling.ray_count();
                out.ready.push_back({out.filling.Take(), count});
            }
            ready.swap(out.ready);
        }
        for (Message& m : ready) {
            // At most max_sends_in_flight to one rank: wait for the oldest, receiving meanwhile
            // (the rank we wait for may itself be waiting to send to us).
            auto last_sign = std::chrono::steady_clock::now();
            while (int(posted[size_t(dest)].size()) >= options.max_sends_in_flight) {
                NAVE_ASSIGN_OR_RETURN(bool progressed, Step());
                if (progressed) {
                    last_sign = std::chrono::steady_clock::now();
                } else if (options.stall_timeout_s > 0 &&
                           SecondsSince(last_sign) > options.stall_timeout_s) {
                    return InternalError(
                        "rank {} of {} waited {:.0f} s for rank {} to take its rays, and it took "
                        "none: that rank has stopped or hangs (--rank-timeout sets this wait)",
                        rank, size, SecondsSince(last_sign), dest);
                }
                if (!progressed) std::this_thread::sleep_for(std::chrono::microseconds(50));
            }
            Posted& p = posted[size_t(dest)].emplace_back();
            p.bytes = options.pack_messages ? PackRayMessage(m.bytes) : std::move(m.bytes);
            NAVE_RETURN_IF_ERROR(MpiStatus(MPI_Isend(p.bytes.data(), int(p.bytes.size()), MPI_BYTE,
                                                     dest, kRaysTag, rays_comm, &p.request),
                                           "MPI_Isend"));
            counts.records_sent += m.rays;
            counts.messages_sent += 1;
            counts.bytes_sent += p.bytes.size();
        }
    }
    return Status::Ok();
}

StatusOr<bool> MpiRayExchange::Impl::CompleteSends(std::deque<Posted>& list) {
    bool any = false;
    for (auto it = list.begin(); it != list.end();) {
        int done = 0;
        NAVE_RETURN_IF_ERROR(
            MpiStatus(MPI_Test(&it->request, &done, MPI_STATUS_IGNORE), "MPI_Test"));
        if (done) {
            it = list.erase(it);
            any = true;
        } else {
            ++it;
        }
    }
    return any;
}

StatusOr<bool> MpiRayExchange::Impl::Receive() {
    bool any = false;
    while (true) {
        int arrived = 0;
        MPI_Status status;
        MPI_Message matched = MPI_MESSAGE_NULL;
        NAVE_RETURN_IF_ERROR(
            MpiStatus(MPI_Improbe(MPI_ANY_SOURCE, kRaysTag, rays_comm, &arrived, &matched, &status),
                      "MPI_Improbe"));
        if (!arrived) return any;
        int bytes = 0;
        NAVE_RETURN_IF_ERROR(MpiStatus(MPI_Get_count(&status, MPI_BYTE, &bytes), "MPI_Get_count"));
        receive_buffer.resize(size_t(std::max(bytes, 0)));
        NAVE_RETURN_IF_ERROR(ReceiveMatched(&matched, bytes, status.MPI_SOURCE));
        const std::string what =
            fmt::format("rays from rank {} to rank {}", status.MPI_SOURCE, rank);
        std::span<const std::byte> message = receive_buffer;
        if (IsPackedRayMessage(message)) {
            // A sender's raw message is about its message_bytes (the same option as this rank's),
            // a few group headers more.
            NAVE_RETURN_IF_ERROR(
                UnpackRayMessage(message, 2 * options.message_bytes + (1 << 16), what, &unpacked));
            message = unpacked;
        }
        // Whole and for this rank's bricks only, before any ray is queued: a damaged message
        // delivers nothing.
        uint32_t foreign_slot = UINT32_MAX;
        NAVE_RETURN_IF_ERROR(ForEachRayGroup(message, uint32_t(owners.size()), what,
                                             [&](uint32_t slot, std::span<const RayRecord>) {
                                                 if (!TracedBy(owners[slot], rank))
                                                     foreign_slot = slot;
                                             })
                                 .status());
        if (foreign_slot != UINT32_MAX) {
            return DataLossError("{}: brick slot {} belongs to rank {}, not this one", what,
                                 foreign_slot, owners[foreign_slot]);
        }
        NAVE_ASSIGN_OR_RETURN(const uint64_t rays,
                              ForEachRayGroup(message, uint32_t(owners.size()), what,
                                              [&](uint32_t slot, std::span<const RayRecord> group) {
                                                  queues.Push(slot, group.data(), group.size());
                                              }));
        counts.records_received += rays;
        counts.messages_received += 1;
        counts.bytes_received += uint64_t(bytes);
        any = true;
    }
}

Status MpiRayExchange::Impl::Report(bool now) {
    NAVE_RETURN_IF_ERROR(CompleteSends(reports).status());
    if (bar == nullptr || rank == 0) return Status::Ok();
    if (!now && SecondsSince(last_report) < kProgressReportSeconds) return Status::Ok();
    const uint64_t done = bar->done();
    if (done == reported) return Status::Ok();
    const uint64_t gained = done - reported;
    Posted& p = reports.emplace_back();
    p.bytes.resize(sizeof(gained));
    std::memcpy(p.bytes.data(), &gained, sizeof(gained));
    NAVE_RETURN_IF_ERROR(MpiStatus(MPI_Isend(p.bytes.data(), int(p.bytes.size()), MPI_BYTE, 0,
                                             kProgressTag, rays_comm, &p.request),
                                   "MPI_Isend"));
    reported = done;
    last_report = std::chrono::steady_clock::now();
    ++reports_sent;
    return Status::Ok();
}

Status MpiRayExchange::Impl::ReceiveMatched(MPI_Message* matched, int bytes, int source) {
    // Not MPI_Mrecv: a large message comes in pieces that its sender pushes as it progresses, and
    // a sender stopped mid-message would hold a blocking receive (and this rank's timeout) forever.
    MPI_Request request = MPI_REQUEST_NULL;
    NAVE_RETURN_IF_ERROR(MpiStatus(
        MPI_Imrecv(receive_buffer.data(), bytes, MPI_BYTE, matched, &request), "MPI_Imrecv"));
    return WaitForRequest(&request, options.stall_timeout_s, [&](double waited) {
        return InternalError(
            "rank {} of {} waited {:.0f} s for the rest of a batch of rays from rank {}, and it "
            "never came: that rank has stopped or hangs (--rank-timeout sets this wait)",
            rank, size, waited, source);
    });
}

Status MpiRayExchange::Impl::ReceiveReports() {
    if (rank != 0) return Status::Ok();
    while (true) {
        int arrived = 0;
        MPI_Status status;
        NAVE_RETURN_IF_ERROR(MpiStatus(
            MPI_Iprobe(MPI_ANY_SOURCE, kProgressTag, rays_comm, &arrived, &status), "MPI_Iprobe"));
        if (!arrived) return Status::Ok();
        NAVE_RETURN_IF_ERROR(TakeReport(status.MPI_SOURCE));
    }
}

Status MpiRayExchange::Impl::TakeReport(int source) {
    uint64_t gained = 0;
    NAVE_RETURN_IF_ERROR(MpiStatus(MPI_Recv(&gained, int(sizeof(gained)), MPI_BYTE, source,
                                            kProgressTag, rays_comm, MPI_STATUS_IGNORE),
                                   "MPI_Recv"));
    ++reports_received;
    if (bar != nullptr) bar->Add(gained);
    return Status::Ok();
}

StatusOr<bool> MpiRayExchange::Impl::Step() {
    NAVE_RETURN_IF_ERROR(Report(false));
    NAVE_RETURN_IF_ERROR(ReceiveReports());
    bool any = false;
    for (int dest = 0; dest < size; ++dest) {
        if (dest == rank) continue;
        NAVE_ASSIGN_OR_RETURN(bool completed, CompleteSends(posted[size_t(dest)]));
        any = any || completed;
    }
    NAVE_ASSIGN_OR_RETURN(bool received, Receive());
    return any || received;
}

Status MpiRayExchange::Progress() {
    NAVE_RETURN_IF_ERROR(impl_->PostReady(false));
    return impl_->Step().status();
}

StatusOr<bool> MpiRayExchange::WaitForRaysOrEnd() {
    Impl& m = *impl_;
    const auto start = std::chrono::steady_clock::now();
    NAVE_RETURN_IF_ERROR(m.PostReady(true));
    while (true) {
        // This rank's counts while it is idle; the sum over ranks, computed while rays still
        // arrive. Two rounds in a row with the same sums and sent = received: no rank sent or
        // received between them, each was idle at both, so none has a ray or one in flight.
        const uint64_t local[2] = {m.counts.records_sent, m.counts.records_received};
        uint64_t sums[2] = {0, 0};
        MPI_Request request = MPI_REQUEST_NULL;
        NAVE_RETURN_IF_ERROR(
            MpiStatus(MPI_Iallreduce(local, sums, 2, MPI_UINT64_T, MPI_SUM, m.sum_comm, &request),
                      "MPI_Iallreduce"));
        m.counts.termination_rounds += 1;
        int done = 0;
        auto last_sign = std::chrono::steady_clock::now();  // of the other ranks' life
        while (true) {
            NAVE_RETURN_IF_ERROR(
                MpiStatus(MPI_Test(&request, &done, MPI_STATUS_IGNORE), "MPI_Test"));
            if (done) break;
            const uint64_t received = m.counts.messages_received;
            NAVE_ASSIGN_OR_RETURN(bool progressed, m.Step());
            if (m.counts.messages_received != received) {
                last_sign = std::chrono::steady_clock::now();
            } else if (m.options.stall_timeout_s > 0 &&
                       SecondsSince(last_sign) > m.options.stall_timeout_s) {
                // Another rank neither sends rays nor joins the sum: stopped, stuck, or in a
                // batch longer than the timeout. The error ends the job (MPI_Abort).
                return InternalError(
                    "rank {} of {} waited {:.0f} s for rays or for the other ranks to finish "
                    "their batches, and none came: a rank has stopped or hangs (--rank-timeout "
                    "sets this wait)",
                    m.rank, m.size, SecondsSince(last_sign));
            }
            // Ranks may share cores (mpirun --oversubscribe): a waiting rank yields them.
            if (!progressed) std::this_thread::sleep_for(std::chrono::microseconds(50));
        }
        const bool unchanged =
            m.have_last_sums && sums[0] == m.last_sums[0] && sums[1] == m.last_sums[1];
        m.last_sums[0] = sums[0];
        m.last_sums[1] = sums[1];
        m.have_last_sums = true;
        if (unchanged && sums[0] == sums[1]) {
            m.have_last_sums = false;  // the next drain starts its own rounds
            m.counts.idle_seconds += SecondsSince(start);
            return true;
        }
        if (m.queues.TotalWaiting() > 0) {
            m.counts.idle_seconds += SecondsSince(start);
            return false;
        }
    }
}

Status MpiRayExchange::SetOwners(std::vector<int> owners) {
    Impl& m = *impl_;
    if (owners.size() != m.owners.size()) {
        return InvalidArgumentError("ray exchange: {} new owners for {} brick slots", owners.size(),
                                    m.owners.size());
    }
    NAVE_RETURN_IF_ERROR(CheckOwners(owners, m.size));
    for (const auto& out : m.outgoing) {
        std::lock_guard<std::mutex> lock(out->mutex);
        if (!out->filling.empty() || !out->ready.empty())
            return InternalError("ray exchange: bricks change owners while rays are on their way");
    }
    m.owners = std::move(owners);
    return Status::Ok();
}

void MpiRayExchange::ShareProgress(ProgressBar* bar) {
    impl_->bar = bar;
    impl_->reported = bar != nullptr ? bar->done() : 0;
    impl_->last_report = std::chrono::steady_clock::now();
}

Status MpiRayExchange::FinishProgress() {
    Impl& m = *impl_;
    NAVE_RETURN_IF_ERROR(m.Report(true));
    for (Impl::Posted& p : m.reports) {
        NAVE_RETURN_IF_ERROR(MpiStatus(MPI_Wait(&p.request, MPI_STATUS_IGNORE), "MPI_Wait"));
    }
    m.reports.clear();
    // Every report sent is received before the bar goes: rank 0 learns how many there were.
    uint64_t sent = 0;
    MPI_Request request = MPI_REQUEST_NULL;
    NAVE_RETURN_IF_ERROR(MpiStatus(
        MPI_Iallreduce(&m.reports_sent, &sent, 1, MPI_UINT64_T, MPI_SUM, m.sum_comm, &request),
        "MPI_Iallreduce"));
    NAVE_RETURN_IF_ERROR(WaitForCollective(&request, "the sum of progress reports", m.sum_comm,
                                           m.options.stall_timeout_s));
    while (m.rank == 0 && m.reports_received < sent)
        NAVE_RETURN_IF_ERROR(m.TakeReport(MPI_ANY_SOURCE));
    m.bar = nullptr;
    return Status::Ok();
}

StatusOr<ExchangeCounts> MpiRayExchange::TotalCounts() const {
    const ExchangeCounts& c = impl_->counts;
    const uint64_t local[7] = {c.records_sent,      c.records_received, c.messages_sent,
                               c.messages_received, c.bytes_sent,       c.bytes_received,
                               c.termination_rounds};
    uint64_t sums[7] = {};
    double idle = 0;
    MPI_Request requests[2] = {MPI_REQUEST_NULL, MPI_REQUEST_NULL};
    NAVE_RETURN_IF_ERROR(MpiStatus(
        MPI_Iallreduce(local, sums, 7, MPI_UINT64_T, MPI_SUM, impl_->sum_comm, &requests[0]),
        "MPI_Iallreduce"));
    NAVE_RETURN_IF_ERROR(MpiStatus(MPI_Iallreduce(&c.idle_seconds, &idle, 1, MPI_DOUBLE, MPI_SUM,
                                                  impl_->sum_comm, &requests[1]),
                                   "MPI_Iallreduce"));
    for (MPI_Request& r : requests) {
        NAVE_RETURN_IF_ERROR(WaitForCollective(&r, "the closing sum of the exchange",
                                               impl_->sum_comm, impl_->options.stall_timeout_s));
    }
    ExchangeCounts total{sums[0], sums[1], sums[2], sums[3], sums[4], sums[5], sums[6], idle};
    if (total.records_sent != total.records_received ||
        total.messages_sent != total.messages_received) {
        return InternalError(
            "ray exchange: the ranks sent {} rays in {} messages and received {} in {}: rays were "
            "lost or counted twice",
            total.records_sent, total.messages_sent, total.records_received,
            total.messages_received);
    }
    return total;
}

}  // namespace nave::render
