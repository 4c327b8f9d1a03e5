#include "src/render/integrators/render_summary.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "src/core/check.h"
#include "src/core/memory.h"
#include "src/core/progress.h"

namespace nave::render {
namespace {

using Unit = RenderFact::Unit;

bool Photon(const RenderSettings& settings) {
    return settings.mode == RenderSettings::Mode::kPhoton;
}

}  // namespace

std::string RenderFact::MetadataText() const {
    switch (unit) {
        case Unit::kCount:
        case Unit::kBytes:
            return std::to_string(integer);
        case Unit::kBudget:
            return integer > 0 ? std::to_string(integer) : std::string("in-core");
        case Unit::kSeconds:
            return fmt::format("{:.3f}s", real);
        case Unit::kPerSecond:
        case Unit::kRatio:
            return fmt::format("{:.6g}", real);
    }
    return std::string();
}

std::string RenderFact::DisplayText() const {
    switch (unit) {
        case Unit::kCount:
            return FormatCount(double(integer));
        case Unit::kBytes:
            return FormatBytes(integer);
        case Unit::kBudget:
            return integer > 0 ? FormatBytes(integer) : std::string("in-core");
        case Unit::kSeconds:
            return FormatDuration(real);
        case Unit::kPerSecond:
            return FormatCount(real);
        case Unit::kRatio:
            return fmt::format("{:.3g}", real);
    }
    return std::string();
}

RenderSummary::RenderSummary(const RenderSettings& settings, const RenderStats& stats,
                             const std::optional<TextureCacheFacts>& textures)
    : settings_(settings) {
    const PagerStats& r = stats.residency;
    constexpr std::string_view kStats = kStatisticsAttribute;
    // nave:statistics, in the order bench/ scripts and users know.
    AddReal(kStats, "wall", Unit::kSeconds, stats.wall_seconds);
    Add(kStats, "rays", Unit::kCount, stats.rays);
    Add(kStats, "segments", Unit::kCount, stats.segments_traced);
    Add(kStats, "shadow_segments", Unit::kCount, stats.shadow_segments);
    Add(kStats, "photons", Unit::kCount, stats.photons);
    Add(kStats, "brick_moves", Unit::kCount, stats.brick_moves);
    Add(kStats, "batches", Unit::kCount, stats.batches);
    Add(kStats, "brick_loads", Unit::kCount, r.loads);
    Add(kStats, "bytes_read", Unit::kBytes, stats.bytes_read);
    // At the end of the render; the terminal's peak memory is the process's at exit.
    Add(kStats, "peak_rss", Unit::kBytes, stats.peak_rss_bytes);
    Add(kStats, "brick_budget", Unit::kBudget, r.brick_budget_bytes);
    Add(kStats, "peak_brick_bytes", Unit::kBytes, r.peak_resident_bytes);
    Add(kStats, "brick_evictions", Unit::kCount, r.evictions);
    Add(kStats, "brick_reloads", Unit::kCount, r.reloads);
    Add(kStats, "prefetch_loads", Unit::kCount, r.prefetch_loads);
    Add(kStats, "resident_hits", Unit::kCount, r.resident_hits);
    AddReal(kStats, "stall", Unit::kSeconds, r.stall_seconds);
    Add(kStats, "brick_cache_reads", Unit::kCount, stats.brick_cache_reads);
    Add(kStats, "brick_cache_disk_bytes", Unit::kBytes, stats.brick_cache_disk_bytes);
    Add(kStats, "spilled_rays", Unit::kCount, stats.spilled_rays);
    Add(kStats, "spill_bytes_written", Unit::kBytes, stats.spill_bytes_written);
    Add(kStats, "memory_returns", Unit::kCount, r.memory_returns);
    AddReal(kStats, "noise_relmse", Unit::kRatio, stats.noise_relmse);
    ranks_ = stats.ranks;
    if (stats.ranks > 1) {
        Add(kStats, "ranks", Unit::kCount, uint64_t(stats.ranks));
        Add(kStats, "rays_between_ranks", Unit::kCount, stats.exchange.records_sent);
        Add(kStats, "messages_between_ranks", Unit::kCount, stats.exchange.messages_sent);
        Add(kStats, "bytes_between_ranks", Unit::kBytes, stats.exchange.bytes_sent);
        AddReal(kStats, "ranks_idle", Unit::kSeconds, stats.exchange.idle_seconds);
        Add(kTerminalOnly, "termination_rounds", Unit::kCount, stats.exchange.termination_rounds);
        Add(kStats, "rebalances", Unit::kCount, uint64_t(stats.rebalances));
    }

    // The terminal's own: rates, and counts the metadata leaves to the settings or leaves out.
    const double secs = std::max(1e-9, stats.wall_seconds);
    AddReal(kTerminalOnly, "rays_per_s", Unit::kPerSecond, double(stats.rays) / secs);
    AddReal(kTerminalOnly, "photons_per_s", Unit::kPerSecond, double(stats.photons) / secs);
    Add(kTerminalOnly, "peak_queue_bytes", Unit::kBytes, stats.peak_queue_bytes);
    Add(kTerminalOnly, "brick_acquires", Unit::kCount, r.acquires);
    Add(kTerminalOnly, "spill_peak_disk_bytes", Unit::kBytes, stats.spill_peak_disk_bytes);
    Add(kTerminalOnly, "brick_cache_written", Unit::kCount, stats.brick_cache_written);
    Add(kTerminalOnly, "brick_cache_mesh_bytes", Unit::kBytes, stats.brick_cache_mesh_bytes);
    Add(kTerminalOnly, "samples_per_pixel", Unit::kCount, uint64_t(stats.samples_per_pixel));
    Add(kTerminalOnly, "iterations", Unit::kCount, uint64_t(stats.iterations));
    Add(kTerminalOnly, "guide_cells", Unit::kCount, stats.guide_cells);
    Add(kTerminalOnly, "guide_cells_guiding", Unit::kCount, stats.guide_cells_guiding);
    Add(kTerminalOnly, "sky_window_regions", Unit::kCount, stats.sky_window_regions);

    if (textures) {
        has_textures_ = true;
        Add(kTexturesAttribute, "cache_cap", Unit::kBytes, textures->cap_bytes);
        Add(kTexturesAttribute, "bytes_read", Unit::kBytes, textures->bytes_read);
        Add(kTerminalOnly, "texture_held_bytes", Unit::kBytes, textures->held_bytes);
    }
}

RenderFact& RenderSummary::Push(std::string_view attribute, std::string_view key, Unit unit) {
    RenderFact& fact = facts_.emplace_back();
    fact.attribute = attribute;
    fact.key = key;
    fact.unit = unit;
    return fact;
}

void RenderSummary::Add(std::string_view attribute, std::string_view key, Unit unit,
                        uint64_t integer) {
    Push(attribute, key, unit).integer = integer;
}

void RenderSummary::AddReal(std::string_view attribute, std::string_view key, Unit unit,
                            double real) {
    Push(attribute, key, unit).real = real;
}

void RenderSummary::RecordProcessPeak(uint64_t bytes) {
    Add(kTerminalOnly, "process_peak_rss", Unit::kBytes, bytes);
}

const RenderFact& RenderSummary::Get(std::string_view attribute, std::string_view key) const {
    const auto it = std::find_if(facts_.begin(), facts_.end(), [&](const RenderFact& f) {
        return f.attribute == attribute && f.key == key;
    });
    NAVE_CHECK(it != facts_.end()) << "no fact " << key << " in '" << attribute << "'";
    return *it;
}

std::string RenderSummary::MetadataText(std::string_view attribute) const {
    std::string text;
    for (const RenderFact& f : facts_) {
        if (f.attribute != attribute) continue;
        if (!text.empty()) text += ' ';
        text += fmt::format("{}={}", f.key, f.MetadataText());
    }
    return text;
}

std::string RenderSummary::SettingsText() const {
    const RenderSettings& s = settings_;
    return fmt::format(
        "mode={} spp={} iterations={} photons_per_iteration={} seed={} max_depth={} threads={} "
        "noise_target={} time_limit_s={}",
        Photon(s) ? "photon" : "path", Integer("samples_per_pixel"), Integer("iterations"),
        s.photons_per_iteration, s.seed, s.max_depth, s.threads, s.noise_target, s.time_limit_s);
}

std::string RenderSummary::NoiseLine() const {
    const bool photon = Photon(settings_);
    const uint64_t done = Integer(photon ? "iterations" : "samples_per_pixel");
    const RenderFact& noise = Get(kStatisticsAttribute, "noise_relmse");
    const bool estimated = std::isfinite(noise.real);
    std::string line =
        estimated ? fmt::format("noise: estimated relMSE {} after {} {}", noise.DisplayText(), done,
                                photon ? "iterations" : "samples per pixel")
                  : fmt::format("noise: not estimated (it takes two {})",
                                photon ? "iterations" : "passes");
    if (settings_.noise_target > 0) {
        line += estimated && noise.real <= settings_.noise_target
                    ? fmt::format(", target {:.3g} reached", settings_.noise_target)
                    : fmt::format(", target {:.3g} not reached (raise --{} or render.time_limit_s)",
                                  settings_.noise_target, photon ? "iterations" : "spp");
    }
    if (settings_.path_guiding && !photon) {
        line += fmt::format("; path guide: {} cells learning, {} guiding", Integer("guide_cells"),
                            Integer("guide_cells_guiding"));
    }
    if (settings_.LearnsSkyWindows())
        line +=
            fmt::format("; sky windows: {} regions chose theirs", Integer("sky_window_regions"));
    return line;
}

std::vector<std::string> RenderSummary::TerminalLines(const std::string& memory_text) const {
    auto stat = [&](std::string_view key) { return Get(kStatisticsAttribute, key).DisplayText(); };
    auto own = [&](std::string_view key) { return Get(kTerminalOnly, key).DisplayText(); };
    std::vector<std::string> lines;
    lines.push_back(fmt::format(
        "time {}, {} rays/s ({} rays: {} segments traced, {} shadow segments), {} photons/s",
        stat("wall"), own("rays_per_s"), stat("rays"), stat("segments"), stat("shadow_segments"),
        own("photons_per_s")));
    lines.push_back(fmt::format(
        "rays moved between bricks {}, batches {}, loads {}, read {}, peak memory {} ({} "
        "bytes), peak queues {}",
        stat("brick_moves"), stat("batches"), stat("brick_loads"), stat("bytes_read"),
        own("process_peak_rss"), Integer("process_peak_rss"), own("peak_queue_bytes")));
    lines.push_back(NoiseLine());
    if (ranks_ > 1) {
        lines.push_back(fmt::format(
            "ranks {}: {} rays sent between them in {} messages ({}), idle {} in all, {} rounds "
            "to find the ends of drains, bricks re-balanced {} times by measured work; the counts "
            "above are all ranks', the bricks below rank 0's",
            stat("ranks"), stat("rays_between_ranks"), stat("messages_between_ranks"),
            stat("bytes_between_ranks"), stat("ranks_idle"), own("termination_rounds"),
            stat("rebalances")));
    }

    const RenderFact& budget = Get(kStatisticsAttribute, "brick_budget");
    const RenderFact& peak = Get(kStatisticsAttribute, "peak_brick_bytes");
    const uint64_t memory_returns = Get(kStatisticsAttribute, "memory_returns").integer;
    std::string budget_text = budget.DisplayText();
    if (budget.integer > 0) {
        budget_text = "budget " + budget_text;
        if (!memory_text.empty()) budget_text += " (--memory " + memory_text + ")";
    }
    lines.push_back(fmt::format(
        "bricks: {}, peak resident {}{}, evictions {}, reloads {}, prefetched {}, resident when "
        "needed {} of {}, workers stalled on loads {}{}",
        budget_text, peak.DisplayText(),
        budget.integer > 0 ? fmt::format(" ({:.0f}% of budget)",
                                         100.0 * double(peak.integer) / double(budget.integer))
                           : std::string(),
        stat("brick_evictions"), stat("brick_reloads"), stat("prefetch_loads"),
        stat("resident_hits"), own("brick_acquires"), stat("stall"),
        memory_returns > 0 ? fmt::format(", free pages given back {} times {}", memory_returns,
                                         memory_text.empty() ? "as they piled up" : "near --memory")
                           : std::string()));
    if (Get(kStatisticsAttribute, "spilled_rays").integer > 0) {
        lines.push_back(fmt::format(
            "ray queues: {} rays spilled to disk ({} written, at most {} on disk at "
            "once)",
            stat("spilled_rays"), stat("spill_bytes_written"), own("spill_peak_disk_bytes")));
    }
    if (Integer("brick_cache_written") > 0) {
        lines.push_back(fmt::format(
            "brick cache: {} bricks decoded once, {} reloads read back, {} on disk ({} decoded)",
            own("brick_cache_written"), stat("brick_cache_reads"), stat("brick_cache_disk_bytes"),
            own("brick_cache_mesh_bytes")));
    }
    if (has_textures_) {
        lines.push_back(fmt::format(
            "textures: read {} through a {} tile cache ({} held at the end)",
            Get(kTexturesAttribute, "bytes_read").DisplayText(),
            Get(kTexturesAttribute, "cache_cap").DisplayText(), own("texture_held_bytes")));
    }
    return lines;
}

}  // namespace nave::render
