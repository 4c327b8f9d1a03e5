#include "src/imaging/oiio/oiio_texture_cache.h"

#include <OpenImageIO/imageio.h>
#include <OpenImageIO/texture.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <vector>

#include "src/core/check.h"
#include "src/imaging/oiio/oiio_status.h"

namespace nave::imaging::oiio {
namespace {

class OiioTextureCache final : public TextureCache {
  public:
    explicit OiioTextureCache(OIIO::TextureSystem* system) : system_(system) {}
    ~OiioTextureCache() override;
    Status Configure(size_t max_memory_bytes);

    StatusOr<TextureRef> Open(const std::filesystem::path& path) override;
    Status Lookup(TextureRef texture, float s, float t, const TextureFootprint& footprint,
                  int first_channel, int num_channels, float* result,
                  TextureWrap wrap) const override;
    const TextureInfo& info(TextureRef texture) const override;
    StatusOr<std::string> StringAttribute(TextureRef texture,
                                          const std::string& name) const override;
    size_t max_memory_bytes() const override { return max_memory_bytes_; }
    Status SetMaxMemoryBytes(size_t max_memory_bytes) override {
        return Configure(max_memory_bytes);
    }
    uint64_t opened_pixel_bytes() const override {
        std::lock_guard<std::mutex> lock(mutex_);
        uint64_t sum = 0;
        for (const auto& e : entries_) sum += e->info.pixel_bytes;
        return sum;
    }
    size_t memory_used_bytes() const override;
    uint64_t bytes_read() const override;
    std::string StatsReport(int level) const override { return system_->getstats(level); }

  private:
    struct Entry {
        OIIO::TextureSystem::TextureHandle* handle = nullptr;
        TextureInfo info;
    };
    OIIO::TextureSystem* system_;  // owned
    size_t max_memory_bytes_ = 0;
    mutable std::mutex mutex_;  // guards entries_ growth (entries themselves never move)
    std::vector<std::unique_ptr<Entry>> entries_;
};

Status OiioTextureCache::Configure(size_t max_memory_bytes) {
    OIIO::TextureSystem* ts = system_;
    ts->attribute("max_memory_MB", float(double(max_memory_bytes) / (1024.0 * 1024.0)));
    // Untiled files (JPEG, PNG, TGA as exported) are read in 64-pixel tiles rather than whole,
    // and get MIP levels built on demand, so they too stay within the cap.
    ts->attribute("autotile", 64);
    ts->attribute("automip", 1);
    // Errors are returned as Status; OIIO must not print them itself.
    ts->attribute("max_errors_per_file", 1);
    float effective_mb = 0.f;
    if (!ts->getattribute("max_memory_MB", effective_mb))
        return InternalError("OpenImageIO: cannot read back max_memory_MB");
    max_memory_bytes_ = size_t(double(effective_mb) * 1024.0 * 1024.0);
    return Status::Ok();
}

// Texture systems are never destroyed: a destroyed one leaves tile references in the per-thread
// data of the worker threads that used it, and OpenImageIO 2.4 then drives another cache's memory
// count below zero (an assertion in imagecache_pvt.h when a process makes caches one after
// another). A finished cache's system is emptied and kept here for the next cache; the pool lives
// as long as the process (reachable, not leaked).
std::mutex& PoolMutex() {
    static std::mutex mutex;
    return mutex;
}
std::vector<OIIO::TextureSystem*>& Pool() {
    static auto* pool = new std::vector<OIIO::TextureSystem*>();
    return *pool;
}

OiioTextureCache::~OiioTextureCache() {
    system_->invalidate_all(/*force=*/true);
    system_->reset_stats();
    std::lock_guard<std::mutex> lock(PoolMutex());
    Pool().push_back(system_);
}

StatusOr<TextureRef> OiioTextureCache::Open(const std::filesystem::path& path) {
    OIIO::TextureSystem* ts = system_;
    OIIO::ustring name(path.string());
    OIIO::TextureSystem::TextureHandle* handle = ts->get_texture_handle(name);
    OIIO::ImageSpec spec;
    if (handle == nullptr || !ts->good(handle) || !ts->get_imagespec(handle, nullptr, 0, spec))
        return OiioError(path, "cannot open texture", TakeError(*ts));
    auto entry = std::make_unique<Entry>();
    entry->handle = handle;
    entry->info.path = path;
    entry->info.width = spec.width;
    entry->info.height = spec.height;
    entry->info.channels = spec.nchannels;
    entry->info.tiled = spec.tile_width > 0;
    int levels = 1;
    if (ts->get_texture_info(handle, nullptr, 0, OIIO::ustring("miplevels"), OIIO::TypeInt,
                             &levels))
        entry->info.mip_levels = levels;
    // What the cache holds for it: whole tiles (64 when the file is untiled: autotile) of 4-byte
    // floats, as OpenImageIO's cache may widen half and 8-bit texels; the finest level and a third
    // more for the coarser ones (each a quarter of the one before).
    const uint64_t tile_w = spec.tile_width > 0 ? uint64_t(spec.tile_width) : 64;
    const uint64_t tile_h = spec.tile_height > 0 ? uint64_t(spec.tile_height) : 64;
    const uint64_t padded = (uint64_t(spec.width) + tile_w - 1) / tile_w * tile_w *
                            ((uint64_t(spec.height) + tile_h - 1) / tile_h * tile_h);
    entry->info.pixel_bytes = padded * uint64_t(spec.nchannels) * 4 * 4 / 3;
    std::lock_guard<std::mutex> lock(mutex_);
    entries_.push_back(std::move(entry));
    return TextureRef{entries_.back().get()};
}

const TextureInfo& OiioTextureCache::info(TextureRef texture) const {
    NAVE_CHECK(texture.entry != nullptr);
    return static_cast<const Entry*>(texture.entry)->info;
}

Status OiioTextureCache::Lookup(TextureRef texture, float s, float t,
                                const TextureFootprint& footprint, int first_channel,
                                int num_channels, float* result, TextureWrap wrap) const {
    NAVE_CHECK(texture.entry != nullptr);
    const Entry& e = *static_cast<const Entry*>(texture.entry);
    OIIO::TextureOpt opt;
    opt.firstchannel = first_channel;
    opt.interpmode = OIIO::TextureOpt::InterpBilinear;
    opt.mipmode = OIIO::TextureOpt::MipModeTrilinear;
    OIIO::TextureOpt::Wrap w = wrap == TextureWrap::kRepeat  ? OIIO::TextureOpt::WrapPeriodic
                               : wrap == TextureWrap::kClamp ? OIIO::TextureOpt::WrapClamp
                                                             : OIIO::TextureOpt::WrapBlack;
    opt.swrap = w;
    opt.twrap = w;
    opt.fill = 0.f;
    OIIO::TextureSystem* ts = system_;
    if (!ts->texture(e.handle, nullptr, opt, s, t, footprint.dsdx, footprint.dtdx, footprint.dsdy,
                     footprint.dtdy, num_channels, result))
        return OiioError(e.info.path, "texture lookup failed", TakeError(*ts));
    return Status();
}

StatusOr<std::string> OiioTextureCache::StringAttribute(TextureRef texture,
                                                        const std::string& name) const {
    NAVE_CHECK(texture.entry != nullptr);
    const Entry& e = *static_cast<const Entry*>(texture.entry);
    OIIO::TextureSystem* ts = system_;
    OIIO::ImageSpec spec;
    if (!ts->get_imagespec(e.handle, nullptr, 0, spec))
        return OiioError(e.info.path, "cannot read texture header", TakeError(*ts));
    const OIIO::ParamValue* p = spec.find_attribute(name, OIIO::TypeString);
    if (p == nullptr)
        return NotFoundError("{}: no string attribute \"{}\" in the header", e.info.path.string(),
                             name);
    return std::string(p->get_string());
}

size_t OiioTextureCache::memory_used_bytes() const {
    int64_t used = 0;
    system_->getattribute("stat:cache_memory_used", OIIO::TypeInt64, &used);
    return size_t(std::max<int64_t>(used, 0));
}

uint64_t OiioTextureCache::bytes_read() const {
    int64_t bytes = 0;
    system_->getattribute("stat:bytes_read", OIIO::TypeInt64, &bytes);
    return uint64_t(std::max<int64_t>(bytes, 0));
}

}  // namespace

StatusOr<std::unique_ptr<TextureCache>> CreateOiioTextureCache(size_t max_memory_bytes) {
    // Not the shared TextureSystem: each cache has its own ImageCache and so its own budget.
    OIIO::TextureSystem* ts = nullptr;
    {
        std::lock_guard<std::mutex> lock(PoolMutex());
        if (!Pool().empty()) {
            ts = Pool().back();
            Pool().pop_back();
        }
    }
    if (ts == nullptr) ts = OIIO::TextureSystem::create(/*shared=*/false);
    if (ts == nullptr) return InternalError("OpenImageIO: cannot create a texture system");
    auto cache = std::make_unique<OiioTextureCache>(ts);
    NAVE_RETURN_IF_ERROR(cache->Configure(max_memory_bytes));
    return std::unique_ptr<TextureCache>(std::move(cache));
}

}  // namespace nave::imaging::oiio
