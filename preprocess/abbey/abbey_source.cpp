#include "preprocess/abbey/abbey_source.h"

#include <fmt/format.h>

#include <atomic>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <thread>

#include "preprocess/abbey/abbey_plan.h"
#include "preprocess/abbey/glass_textures.h"
#include "preprocess/abbey/materials.h"
#include "preprocess/import/text_parse.h"

namespace nave::preprocess {
namespace {

constexpr size_t kBatchTriangles = 1 << 14;
constexpr size_t kQueueBatches = 4;  // bounded: at most ~4 x 16 K triangles waiting

class AbbeySource final : public TriangleSource {
  public:
    explicit AbbeySource(double detail) : detail_(detail), materials_(abbey::AbbeyMaterials()) {
        parts_total_ = abbey::AbbeyParts(abbey::Detail(detail_)).size();
        producer_ = std::thread([this] { Produce(); });
    }

    ~AbbeySource() override {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            stop_ = true;
        }
        changed_.notify_all();
        producer_.join();
    }

    StatusOr<bool> Next(std::vector<Triangle>& batch, size_t max_triangles) override {
        batch.clear();
        while (batch.size() < max_triangles) {
            if (pending_pos_ == pending_.size()) {
                pending_.clear();
                pending_pos_ = 0;
                std::unique_lock<std::mutex> lock(mutex_);
                changed_.wait(lock, [&] { return !queue_.empty() || done_; });
                if (queue_.empty()) break;
                pending_ = std::move(queue_.front());
                queue_.pop_front();
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
    uint64_t progress_total() const override { return parts_total_; }
    uint64_t memory_bytes() const override {
        return (kQueueBatches + 3) * kBatchTriangles * sizeof(Triangle);
    }
    const ImportWarnings& warnings() const override { return warnings_; }

  private:
    struct Stopped {};

    void Produce() {
        try {
            abbey::Emitter em(
                [this](std::vector<Triangle>& batch) {
                    std::unique_lock<std::mutex> lock(mutex_);
                    changed_.wait(lock, [&] { return queue_.size() < kQueueBatches || stop_; });
                    if (stop_) throw Stopped{};
                    queue_.push_back(std::move(batch));
                    batch = std::vector<Triangle>();
                    batch.reserve(kBatchTriangles);
                    changed_.notify_all();
                },
                kBatchTriangles);
            for (const abbey::AbbeyPart& part : abbey::AbbeyParts(abbey::Detail(detail_))) {
                part.emit(em);
                parts_done_.fetch_add(1);
            }
            em.Flush();
        } catch (const Stopped&) {
        }
        std::lock_guard<std::mutex> lock(mutex_);
        done_ = true;
        changed_.notify_all();
    }

    double detail_;
    std::vector<store::MaterialRecord> materials_;
    ImportWarnings warnings_;
    uint64_t parts_total_ = 0;
    std::atomic<uint64_t> parts_done_{0};
    std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<std::vector<Triangle>> queue_;
    bool stop_ = false, done_ = false;
    std::vector<Triangle> pending_;
    size_t pending_pos_ = 0;
    std::thread producer_;
};

}  // namespace

std::unique_ptr<TriangleSource> MakeAbbeySource(double detail) {
    return std::make_unique<AbbeySource>(detail);
}

StatusOr<std::unique_ptr<TriangleSource>> OpenGenerator(const std::string& spec) {
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
    return MakeAbbeySource(detail);
}

}  // namespace nave::preprocess
