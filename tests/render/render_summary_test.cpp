// The facts at the end of a render: the EXR metadata keeps the keys and formats bench/ scripts
// read, and the terminal summary shows the same facts with the same values.

#include "src/render/integrators/render_summary.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "src/core/memory.h"
#include "src/core/progress.h"

namespace nave::render {
namespace {

constexpr uint64_t kMiB = uint64_t(1) << 20;

/// A paged path render in which every counter differs, so that each value on the terminal can
/// only come from its own fact.
RenderStats BusyStats() {
    RenderStats s;
    s.wall_seconds = 12.345;
    s.rays = 123456789;
    s.segments_traced = 98765432;
    s.shadow_segments = 45678901;
    s.photons = 2345678;
    s.brick_moves = 34567;
    s.batches = 4321;
    s.bytes_read = 7 * (uint64_t(1) << 30) + 123;
    s.peak_rss_bytes = 900 * kMiB;
    s.peak_queue_bytes = 33 * kMiB;
    s.residency.brick_budget_bytes = 512 * kMiB;
    s.residency.peak_resident_bytes = 400 * kMiB;
    s.residency.loads = 321;
    s.residency.prefetch_loads = 150;
    s.residency.reloads = 190;
    s.residency.evictions = 210;
    s.residency.acquires = 1432;
    s.residency.resident_hits = 1111;
    s.residency.memory_returns = 3;
    s.residency.stall_seconds = 3.25;
    s.brick_cache_written = 131;
    s.brick_cache_reads = 180;
    s.brick_cache_disk_bytes = 300 * kMiB;
    s.brick_cache_mesh_bytes = 600 * kMiB;
    s.spilled_rays = 5555555;
    s.spill_bytes_written = 77 * kMiB;
    s.spill_peak_disk_bytes = 44 * kMiB;
    s.noise_relmse = 0.0123456789;
    s.samples_per_pixel = 16;
    return s;
}

std::map<std::string, std::string> ParseKeyValues(const std::string& text) {
    std::map<std::string, std::string> values;
    std::istringstream in(text);
    std::string word;
    while (in >> word) {
        const size_t eq = word.find('=');
        if (eq != std::string::npos) values[word.substr(0, eq)] = word.substr(eq + 1);
    }
    return values;
}

std::string Joined(const std::vector<std::string>& lines) {
    std::string text;
    for (const std::string& line : lines) text += line + "\n";
    return text;
}

// bench/nave_bench.py and the docs read these keys, in this order and format.
TEST(RenderSummaryTest, StatisticsMetadataKeepsItsKeysAndFormats) {
    RenderSettings settings;
    const RenderSummary summary(settings, BusyStats(), std::nullopt);
    EXPECT_EQ(summary.MetadataText(kStatisticsAttribute),
              "wall=12.345s rays=123456789 segments=98765432 shadow_segments=45678901 "
              "photons=2345678 brick_moves=34567 batches=4321 brick_loads=321 "
              "bytes_read=7516192891 peak_rss=943718400 brick_budget=536870912 "
              "peak_brick_bytes=419430400 brick_evictions=210 brick_reloads=190 "
              "prefetch_loads=150 resident_hits=1111 stall=3.250s brick_cache_reads=180 "
              "brick_cache_disk_bytes=314572800 spilled_rays=5555555 "
              "spill_bytes_written=80740352 memory_returns=3 noise_relmse=0.0123457");
    EXPECT_EQ(summary.MetadataText(kTexturesAttribute), "");
    EXPECT_EQ(summary.SettingsText(),
              "mode=path spp=16 iterations=0 photons_per_iteration=200000 seed=1 max_depth=8 "
              "threads=0 noise_target=0 time_limit_s=0");
}

// Every fact of nave:statistics is on the terminal with the value the metadata holds, but the two
// the terminal shows otherwise: the process's peak at exit (image writing included) rather than at
// the render's end, and photons as a rate.
TEST(RenderSummaryTest, TheTerminalShowsTheMetadataFacts) {
    RenderSettings settings;
    RenderSummary summary(settings, BusyStats(), std::nullopt);
    summary.RecordProcessPeak(950 * kMiB);
    const std::string terminal = Joined(summary.TerminalLines("620M"));
    const std::map<std::string, std::string> metadata =
        ParseKeyValues(summary.MetadataText(kStatisticsAttribute));

    // How the terminal words each fact ("{}": its value).
    const std::map<std::string, std::string> phrases = {
        {"wall", "time {},"},
        {"rays", "({} rays:"},
        {"segments", " {} segments traced"},
        {"shadow_segments", " {} shadow segments"},
        {"brick_moves", "rays moved between bricks {},"},
        {"batches", "batches {},"},
        {"brick_loads", " loads {},"},
        {"bytes_read", " read {},"},
        {"brick_budget", "bricks: budget {} (--memory 620M)"},
        {"peak_brick_bytes", "peak resident {} (78% of budget)"},
        {"brick_evictions", "evictions {},"},
        {"brick_reloads", " reloads {},"},
        {"prefetch_loads", "prefetched {},"},
        {"resident_hits", "resident when needed {} of 1432,"},
        {"stall", "workers stalled on loads {}"},
        {"brick_cache_reads", ", {} reloads read back"},
        {"brick_cache_disk_bytes", ", {} on disk (600.0 MiB decoded)"},
        {"spilled_rays", "ray queues: {} rays spilled to disk"},
        {"spill_bytes_written", "({} written, at most 44.0 MiB on disk at once)"},
        {"memory_returns", "free pages given back {} times near --memory"},
        {"noise_relmse", "noise: estimated relMSE {} after 16 samples per pixel"},
    };
    const std::set<std::string> shown_otherwise = {"peak_rss", "photons"};
    for (const RenderFact& fact : summary.facts()) {
        if (fact.attribute != kStatisticsAttribute) continue;
        const std::string key(fact.key);
        ASSERT_EQ(metadata.count(key), 1u) << key;
        EXPECT_EQ(metadata.at(key), fact.MetadataText()) << key;
        if (shown_otherwise.count(key) > 0) continue;
        ASSERT_EQ(phrases.count(key), 1u)
            << key << " is in nave:statistics but not on the terminal";
        const std::string phrase = fmt::format(fmt::runtime(phrases.at(key)), fact.DisplayText());
        EXPECT_NE(terminal.find(phrase), std::string::npos) << key << ": " << phrase << "\n"
                                                            << terminal;
    }
    // The values behind the texts: the metadata's numbers are the stats', the terminal's their
    // display.
    EXPECT_EQ(metadata.at("brick_loads"), "321");
    EXPECT_NE(terminal.find(" loads 321,"), std::string::npos) << terminal;
    EXPECT_NE(terminal.find(" read " + FormatBytes(7 * (uint64_t(1) << 30) + 123) + ","),
              std::string::npos)
        << terminal;
    EXPECT_NE(terminal.find("peak memory 950.0 MiB (996147200 bytes), peak queues 33.0 MiB"),
              std::string::npos)
        << terminal;
    EXPECT_NE(terminal.find(FormatCount(123456789 / 12.345) + " rays/s"), std::string::npos)
        << terminal;
    EXPECT_NE(terminal.find(FormatCount(2345678 / 12.345) + " photons/s"), std::string::npos)
        << terminal;
    EXPECT_NE(terminal.find("brick cache: 131 bricks decoded once"), std::string::npos) << terminal;
}

TEST(RenderSummaryTest, AnInCoreRenderWithoutSpillsOrNoiseEstimate) {
    RenderSettings settings;
    settings.mode = RenderSettings::Mode::kPhoton;
    settings.noise_target = 0.01;
    RenderStats stats;
    stats.wall_seconds = 1.5;
    stats.iterations = 1;
    stats.noise_relmse = std::nan("");
    RenderSummary summary(settings, stats, std::nullopt);
    summary.RecordProcessPeak(10 * kMiB);
    const std::map<std::string, std::string> metadata =
        ParseKeyValues(summary.MetadataText(kStatisticsAttribute));
    EXPECT_EQ(metadata.at("brick_budget"), "in-core");
    EXPECT_EQ(metadata.at("noise_relmse"), "nan");
    const std::vector<std::string> lines = summary.TerminalLines("");
    ASSERT_EQ(lines.size(), 4u) << Joined(lines);
    EXPECT_EQ(lines[2],
              "noise: not estimated (it takes two iterations), target 0.01 not reached (raise "
              "--iterations or render.time_limit_s)");
    EXPECT_EQ(lines[3].rfind("bricks: in-core, peak resident 0 B, evictions 0,", 0), 0u)
        << lines[3];
    EXPECT_EQ(lines[3].find("% of budget"), std::string::npos) << lines[3];
    EXPECT_EQ(lines[3].find("free pages"), std::string::npos) << lines[3];
    EXPECT_EQ(summary.SettingsText().rfind("mode=photon spp=0 iterations=1 ", 0), 0u)
        << summary.SettingsText();
}

TEST(RenderSummaryTest, TexturesInTheirOwnAttributeAndOnTheTerminal) {
    RenderSettings settings;
    settings.path_guiding = true;
    RenderStats stats = BusyStats();
    stats.guide_cells = 512;
    stats.guide_cells_guiding = 300;
    RenderSummary summary(settings, stats, TextureCacheFacts{80 * kMiB, 123456789, 20 * kMiB});
    summary.RecordProcessPeak(10 * kMiB);
    EXPECT_EQ(summary.MetadataText(kTexturesAttribute), "cache_cap=83886080 bytes_read=123456789");
    const std::vector<std::string> lines = summary.TerminalLines("");
    EXPECT_EQ(lines.back(),
              "textures: read 117.7 MiB through a 80.0 MiB tile cache (20.0 MiB held "
              "at the end)");
    EXPECT_EQ(lines[2],
              "noise: estimated relMSE 0.0123 after 16 samples per pixel; path guide: 512 cells "
              "learning, 300 guiding");
    // A budget without --memory (a library caller's) is still a budget.
    EXPECT_NE(Joined(lines).find("bricks: budget 512.0 MiB, peak resident"), std::string::npos)
        << Joined(lines);
}

TEST(RenderSummaryTest, PhotonModeSaysHowManyRegionsLearnedTheirWindows) {
    RenderSettings settings;
    settings.mode = RenderSettings::Mode::kPhoton;
    settings.sky_sampling = RenderSettings::SkySampling::kPortals;
    settings.photon_target = RenderSettings::PhotonTarget::kPortals;
    RenderStats stats = BusyStats();
    stats.iterations = 12;
    stats.sky_window_regions = 1234;
    auto noise_line = [&] {
        RenderSummary summary(settings, stats, std::nullopt);
        summary.RecordProcessPeak(10 * kMiB);
        return summary.TerminalLines("")[2];
    };
    EXPECT_EQ(noise_line(),
              "noise: estimated relMSE 0.0123 after 12 iterations; sky windows: 1234 regions "
              "chose theirs");
    // Without photons aimed at the portals nothing teaches the windows: nothing to say.
    settings.photon_target = RenderSettings::PhotonTarget::kBounds;
    EXPECT_EQ(noise_line(), "noise: estimated relMSE 0.0123 after 12 iterations");
}

}  // namespace
}  // namespace nave::render
