#pragma once
// The facts at the end of a render (time, rays, rates, bricks loaded, bytes read, peak memory,
// noise, spilling, the brick cache, textures), named and valued once. The EXR's metadata
// ("nave:statistics", "nave:textures", "nave:settings") and the terminal summary of `nave render`
// both read them from here, each in its own format; docs/pager.md ("Statistics") pairs the two.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "src/render/integrators/render_stats.h"
#include "src/render/scene/scene_config.h"

namespace nave::render {

/// The metadata attribute that holds a fact as key=value, or kTerminalOnly.
inline constexpr std::string_view kStatisticsAttribute = "nave:statistics";
inline constexpr std::string_view kTexturesAttribute = "nave:textures";
inline constexpr std::string_view kTerminalOnly{};  // empty

/// One fact of a render's summary.
struct RenderFact {
    enum class Unit {
        kCount,      ///< `integer`
        kBytes,      ///< `integer`
        kBudget,     ///< `integer` bytes; 0: none (in-core)
        kSeconds,    ///< `real`
        kPerSecond,  ///< `real`, a rate
        kRatio,      ///< `real`, dimensionless; NaN: not known
    };
    /// Where the metadata holds it (kStatisticsAttribute, kTexturesAttribute), or kTerminalOnly.
    /// Both views are of string literals.
    std::string_view attribute;
    /// Its key in that attribute; unique within it.
    std::string_view key;
    Unit unit = Unit::kCount;
    uint64_t integer = 0;
    double real = 0;

    /// As the metadata writes it: "1234", "1.234s" (seconds, 3 decimals), "in-core" (no budget),
    /// "0.0123457" (ratios, 6 significant digits).
    std::string MetadataText() const;
    /// As the terminal shows it: "12.3 k", "4.5 MiB", "1.2 s", "in-core", "0.0123".
    std::string DisplayText() const;
};

/// What the summary reports of a render's texture cache.
struct TextureCacheFacts {
    uint64_t cap_bytes = 0;   ///< the cache's effective cap
    uint64_t bytes_read = 0;  ///< read from texture files during the render
    uint64_t held_bytes = 0;  ///< tiles held at the end
};

/// The facts of one render. Not thread-safe.
class RenderSummary {
  public:
    /// The facts of a render with `settings` (the render's, as run) that did `stats`;
    /// `textures`: its texture cache's, if it had one.
    RenderSummary(const RenderSettings& settings, const RenderStats& stats,
                  const std::optional<TextureCacheFacts>& textures);

    /// Records the whole process's peak resident size at exit, image writing included (what
    /// --memory bounds): the terminal's peak memory. Before TerminalLines.
    void RecordProcessPeak(uint64_t bytes);

    const std::vector<RenderFact>& facts() const { return facts_; }
    /// The fact `key` of `attribute`; a missing one is a bug (CHECK).
    const RenderFact& Get(std::string_view attribute, std::string_view key) const;
    /// The facts of `attribute` as "key=value key=value ...", in order; empty if it has none.
    std::string MetadataText(std::string_view attribute) const;
    /// "nave:settings": the mode and what was asked of the render, with the passes and iterations
    /// done.
    std::string SettingsText() const;

    /// The terminal summary's lines, without indent or newline: time and rays, noise, bricks, and
    /// when they did anything spilled ray queues, the brick cache and textures. `memory_text`:
    /// --memory as the user wrote it (empty: none).
    std::vector<std::string> TerminalLines(const std::string& memory_text) const;

  private:
    /// A new fact of `key` in `attribute`, its value still to set.
    RenderFact& Push(std::string_view attribute, std::string_view key, RenderFact::Unit unit);
    void Add(std::string_view attribute, std::string_view key, RenderFact::Unit unit,
             uint64_t integer);
    void AddReal(std::string_view attribute, std::string_view key, RenderFact::Unit unit,
                 double real);
    uint64_t Integer(std::string_view key) const { return Get(kTerminalOnly, key).integer; }
    /// The noise line: the render's own estimate and what it stopped on.
    std::string NoiseLine() const;

    RenderSettings settings_;
    bool has_textures_ = false;
    int ranks_ = 1;  // processes of a distributed render
    std::vector<RenderFact> facts_;
};

}  // namespace nave::render
