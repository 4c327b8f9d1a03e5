#pragma once
// Image textures out of core: OpenImageIO's TextureSystem (in nave's plugin, imaging/oiio_plugin.h)
// with its tile cache capped by a byte budget (a share of the renderer's --memory, so the pager can
// count it). Textures are read tile by tile on demand and evicted when the cap is reached; tiled,
// MIP-mapped files (what `nave preprocess` writes) are read most efficiently, untiled ones are
// auto-tiled.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "src/core/status.h"

namespace nave::imaging {

/// The filter footprint of one lookup: the derivatives of the texture coordinates (s, t) along two
/// directions across the pixel's footprint on the surface. All zero means a point sample of the
/// finest level.
struct TextureFootprint {
    float dsdx = 0.f, dtdx = 0.f, dsdy = 0.f, dtdy = 0.f;

    /// An isotropic footprint of width `width` in texture space (1 = the whole texture).
    static TextureFootprint Isotropic(float width) { return {width, 0.f, 0.f, width}; }
};

/// The footprint of a ray cone (Amanatides 1984; the texture level-of-detail of ray cones in
/// Akenine-Möller et al. 2019, "Texture Level of Detail Strategies for Real-Time Ray Tracing", Ray
/// Tracing Gems ch. 20, eq. 20.34-20.35): the cone's width at the hit, `cone_width_m`, widened by
/// the foreshortening 1 / |cos θ| and carried to texture space by the triangle's scale sqrt(A_uv /
/// A_world) (`uv_area` in texture-space units², `world_area_m2` in m²). Isotropic; at most 1.
TextureFootprint RayConeFootprint(float cone_width_m, float cos_theta, float uv_area,
                                  float world_area_m2);

/// How a lookup treats coordinates outside [0, 1].
enum class TextureWrap { kRepeat, kClamp, kBlack };

/// A texture opened in a TextureCache: cheap to copy, valid as long as its cache.
struct TextureRef {
    const void* entry = nullptr;
    explicit operator bool() const { return entry != nullptr; }
};

/// Facts about an opened texture.
struct TextureInfo {
    std::filesystem::path path;
    int width = 0, height = 0, channels = 0;
    int mip_levels = 1;
    bool tiled = false;
    /// What caching the whole texture takes, every MIP level included (whole tiles of floats: an
    /// upper bound).
    uint64_t pixel_bytes = 0;
};

/// Filtered, cached texture lookups with a memory cap. Thread-safe: Open and Lookup may be called
/// from any number of threads.
class TextureCache {
  public:
    /// A cache whose tiles use at most `max_memory_bytes` (OpenImageIO's own floor of 10 MiB
    /// applies; max_memory_bytes() reports the effective cap). Loads the OpenImageIO plugin.
    static StatusOr<std::unique_ptr<TextureCache>> Create(size_t max_memory_bytes);
    virtual ~TextureCache() = default;

    /// Opens `path` (reads its header only). A missing file is NotFound, an unreadable one
    /// IoError, both naming the file and with OpenImageIO's reason.
    virtual StatusOr<TextureRef> Open(const std::filesystem::path& path) = 0;

    /// Filtered lookup of `num_channels` channels from `first_channel` at (s, t) (s to the right,
    /// t downwards, (0, 0) the top-left corner of the image, texel centres at (i + 0.5) / width),
    /// bilinear within and trilinear across MIP levels for the footprint. Missing channels are 0.
    /// Errors name the file.
    virtual Status Lookup(TextureRef texture, float s, float t, const TextureFootprint& footprint,
                          int first_channel, int num_channels, float* result,
                          TextureWrap wrap = TextureWrap::kRepeat) const = 0;

    virtual const TextureInfo& info(TextureRef texture) const = 0;
    /// A string attribute of the file's header (e.g. "nave:band_centres_nm"); NotFound naming the
    /// file and the attribute when absent.
    virtual StatusOr<std::string> StringAttribute(TextureRef texture,
                                                  const std::string& name) const = 0;

    /// The effective cap of the tile cache in bytes.
    virtual size_t max_memory_bytes() const = 0;
    /// Changes the cap (OpenImageIO's floor of 10 MiB applies); tiles beyond it are evicted as
    /// lookups go.
    virtual Status SetMaxMemoryBytes(size_t max_memory_bytes) = 0;
    /// Sum of TextureInfo::pixel_bytes over the textures opened so far: a cap above it buys
    /// nothing.
    virtual uint64_t opened_pixel_bytes() const = 0;
    /// Bytes of tiles held now (OpenImageIO "stat:cache_memory_used").
    virtual size_t memory_used_bytes() const = 0;
    /// Bytes read from texture files so far ("stat:bytes_read").
    virtual uint64_t bytes_read() const = 0;
    /// OpenImageIO's statistics report (level 1-5), for --verbose output.
    virtual std::string StatsReport(int level = 1) const = 0;
};

}  // namespace nave::imaging
