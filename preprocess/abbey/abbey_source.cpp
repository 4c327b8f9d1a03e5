#include "preprocess/abbey/abbey_source.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <thread>
#include <vector>

#include "preprocess/abbey/abbey_plan.h"
#include "preprocess/abbey/glass_textures.h"
#include "preprocess/abbey/materials.h"
#include "preprocess/import/text_parse.h"

namespace nave::preprocess {
namespace {

constexpr size_t kBatchTriangles = 1 << 14;
constexpr size_t kQueueBatches = 4;  // per part in flight: at most ~4 x 16 K triangles waiting

class AbbeySource final : public TriangleSource {
  public:
    AbbeySource(double detail, int threads)
        : detail_(detail),
          materials_(abbey::AbbeyMaterials()),
          parts_(abbey::AbbeyParts(abbey::Detail(detail))),
          channels_(parts_.size()) {
        if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
        threads = int(std::min<size_t>(size_t(threads), std::max<size_t>(1, parts_.size())));
        for (int t = 0; t < threads; ++t) producers_.emplace_back([this] { Produce(); });
    }

    ~AbbeySource() override {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            stop_ = true;
        }
        changed_.notify_all();
        for (std::thread& t : producers_) t.join();
    }

    StatusOr<bool> Next(std::vector<Triangle>& batch, size_t max_triangles) override {
        batch.clear();
        while (batch.size() < max_triangles) {
            if (pending_pos_ == pending_.size()) {
                pending_.clear();
                pending_pos_ = 0;
                std::unique_lock<std::mutex> lock(mutex_);
                // The parts in order: the current one until its producer is done with it.
                for (;;) {
                    if (current_ == parts_.size()) break;
                    Channel& c = channels_[current_];
                    if (!c.batches.empty()) break;
                    if (c.done) {
                        ++current_;
                        parts_done_.fetch_add(1);
                        changed_.notify_all();  // the new current part's producer may go on
                        continue;
                    }
                    changed_.wait(lock);
                }
                if (current_ == parts_.size()) break;
                pending_ = std::move(channels_[current_].batches.front());
                channels_[current_].batches.pop_front();
                --buffered_;
                changed_.notify_all();
            }
            size_t n = std::min(max_triangles - batch.size(), pending_.size() - pending_pos_);
            batch.insert(batch.end(), pending_.begin() + pending_pos_,
                         pending_.begin() + pending_pos_ + n);
            pending_pos_ += n;
        }
        return !batch.empty();
    }

    const std::vector<store::MaterialRecord>& materials() const override { return materials_; }
    std::string name() const override { return fmt::format("abbey:detail={}", detail_); }
    std::string units() const override { return "m"; }
    Status WriteGeneratedTextures(const std::filesystem::path& dir) const override {
        return abbey::WriteGlassTextures(dir);
    }
    uint64_t progress_done() const override { return parts_done_.load(); }
    uint64_t progress_total() const override { return parts_.size(); }
    std::string progress_unit() const override { return "parts"; }
    uint64_t memory_bytes() const override {
        // Waiting batches (BufferCap() for the parts ahead, kQueueBatches for the current one), one
        // being filled per producer, and the consumer's two.
        return (BufferCap() + kQueueBatches + producers_.size() + 2) * kBatchTriangles *
               sizeof(Triangle);
    }
    const ImportWarnings& warnings() const override { return warnings_; }

  private:
    struct Stopped {};
    /// The batches of one part, from its producer to Next.
    struct Channel {
        std::deque<std::vector<Triangle>> batches;
        bool done = false;
    };

    /// Batches that may wait in the channels of parts ahead of the current one, all together:
    /// small parts finish at once, and without this cap the parts queued behind a long one held
    /// 77 MiB at detail 3 (a --memory 64M run peaked at 111 MiB).
    size_t BufferCap() const { return producers_.size() * kQueueBatches; }

    /// Takes the next part nobody has taken, generates it into its channel; until none is left.
    /// A producer waits while its part's channel is full, or, for a part ahead of the current one,
    /// while the channels hold BufferCap() batches. The part being handed on always drains and
    /// every part before it is done, so its producer can always go on.
    void Produce() {
        try {
            for (;;) {
                size_t part;
                {
                    std::lock_guard<std::mutex> lock(mutex_);
                    if (stop_ || next_part_ == parts_.size()) return;
                    part = next_part_++;
                }
                abbey::Emitter em(
                    [this, part](std::vector<Triangle>& batch) {
                        std::unique_lock<std::mutex> lock(mutex_);
                        changed_.wait(lock, [&] {
                            return stop_ || (channels_[part].batches.size() < kQueueBatches &&
                                             (part == current_ || buffered_ < BufferCap()));
                        });
                        if (stop_) throw Stopped{};
                        channels_[part].batches.push_back(std::move(batch));
                        ++buffered_;
                        batch = std::vector<Triangle>();
                        batch.reserve(kBatchTriangles);
                        changed_.notify_all();
                    },
                    kBatchTriangles);
                parts_[part].emit(em);
                em.Flush();
                std::lock_guard<std::mutex> lock(mutex_);
                channels_[part].done = true;
                changed_.notify_all();
            }
        } catch (const Stopped&) {
        }
    }

    double detail_;
    std::vector<store::MaterialRecord> materials_;
    ImportWarnings warnings_;
    const std::vector<abbey::AbbeyPart> parts_;
    std::atomic<uint64_t> parts_done_{0};
    std::mutex mutex_;
    std::condition_variable changed_;
    std::vector<Channel> channels_;  // by part
    size_t next_part_ = 0;           // the next part a producer takes
    size_t current_ = 0;             // the part Next hands on
    size_t buffered_ = 0;            // batches waiting in all channels
    bool stop_ = false;
    std::vector<Triangle> pending_;
    size_t pending_pos_ = 0;
    std::vector<std::thread> producers_;
};

}  // namespace

std::unique_ptr<TriangleSource> MakeAbbeySource(double detail, int threads) {
    return std::make_unique<AbbeySource>(detail, threads);
}

StatusOr<std::unique_ptr<TriangleSource>> OpenGenerator(const std::string& spec, int threads) {
    std::string_view text = spec;
    auto colon = text.find(':');
    std::string_view name = text.substr(0, colon);
    if (name != "abbey") {
        return InvalidArgumentError("generator '{}': unknown; expected 'abbey' or 'abbey:detail=D'",
                                    spec);
    }
    double detail = 1.0;
    if (colon != std::string_view::npos) {
        std::string_view option = text.substr(colon + 1);
        if (option.substr(0, 7) != "detail=") {
            return InvalidArgumentError("generator '{}': unknown option '{}'; expected detail=D",
                                        spec, option);
        }
        float value = 0;
        if (!ParseFloat(option.substr(7), value) || !(value > 0) || value > 1e5) {
            return InvalidArgumentError(
                "generator '{}': detail '{}' must be a number in (0, 100000]", spec,
                option.substr(7));
        }
        detail = value;
    }
    return MakeAbbeySource(detail, threads);
}

}  // namespace nave::preprocess
