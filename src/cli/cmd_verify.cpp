// `nave verify FILE [--json] [--threads N]`: reads every brick of a store, checks its checksums,
// decodes it (its piece of the medium too, through the OpenVDB plugin) and compares it with the
// directory and the medium table. Succeeds (exit 0) only if every brick is intact;
// otherwise lists each damaged brick with its error and fails (exit 1).
#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "src/cli/commands.h"
#include "src/core/json_string.h"
#include "src/core/log.h"
#include "src/core/memory.h"
#include "src/core/progress.h"
#include "src/volumes/vdb_plugin.h"
#include "store/store_reader.h"

namespace nave::cli {
namespace {

struct BadBrick {
    uint32_t id;
    Status status;
};

/// Brick `id`'s piece of the medium decodes to a grid of the voxels the medium table says.
Status VerifyMedium(const store::Store& s, const volumes::VdbPlugin& plugin, uint32_t id) {
    const store::BrickMediumInfo& info = s.bricks()[id].medium;
    NAVE_ASSIGN_OR_RETURN(const std::vector<std::byte> bytes, s.ReadBrickMedium(id));
    const std::string what =
        fmt::format("{} brick {} medium @0x{:x}", s.path().string(), id, info.grid.offset);
    NAVE_ASSIGN_OR_RETURN(std::unique_ptr<volumes::ScalarGrid> grid,
                          plugin.ReadScalarGridBytes(bytes, what));
    if (grid->active_voxels() != info.active_voxels) {
        return DataLossError("{}: decoded {} voxels but the medium table says {}", what,
                             grid->active_voxels(), info.active_voxels);
    }
    return Status::Ok();
}

Status Verify(const std::string& file, bool json, int threads) {
    NAVE_ASSIGN_OR_RETURN(std::unique_ptr<store::Store> s, store::Store::Open(file));
    const std::vector<store::BrickInfo>& bricks = s->bricks();
    const uint32_t brick_count = uint32_t(bricks.size());
    // The medium's pieces decode through the OpenVDB plugin, loaded only for a store that has one.
    const volumes::VdbPlugin* plugin = nullptr;
    if (!s->header().medium_grid.empty()) {
        NAVE_ASSIGN_OR_RETURN(plugin, volumes::LoadVdbPlugin());
    }

    // Bricks are independent and reads are positional: verify on several threads.
    ProgressBar progress("verify", s->header().triangle_count, "triangles");
    std::mutex bad_mutex;
    std::vector<BadBrick> bad;
    tbb::task_arena arena(std::max(1, threads));
    arena.execute([&] {
        tbb::parallel_for(uint32_t(0), brick_count, [&](uint32_t id) {
            Status st = s->VerifyBrick(id);
            if (st.ok() && plugin != nullptr && bricks[id].medium.grid.length > 0)
                st = VerifyMedium(*s, *plugin, id);
            if (!st.ok()) {
                std::lock_guard<std::mutex> lock(bad_mutex);
                bad.push_back({id, st});
            }
            progress.Add(bricks[id].triangle_count);
        });
    });
    progress.Finish();
    std::sort(bad.begin(), bad.end(),
              [](const BadBrick& a, const BadBrick& b) { return a.id < b.id; });

    const double seconds = std::max(progress.ElapsedSeconds(), 1e-9);
    const uint64_t triangles = s->header().triangle_count;
    if (json) {
        std::string out = "{\n";
        out += fmt::format("  \"file\": {},\n", JsonString(file));
        out += fmt::format("  \"ok\": {},\n", bad.empty() ? "true" : "false");
        out += fmt::format("  \"bricks\": {},\n", brick_count);
        out += fmt::format("  \"bad_brick_count\": {},\n", bad.size());
        out += fmt::format("  \"triangles\": {},\n", triangles);
        out += fmt::format("  \"bytes_read\": {},\n", s->bytes_read());
        out += fmt::format("  \"seconds\": {:.6f},\n", seconds);
        out += fmt::format("  \"triangles_per_second\": {:.1f},\n", double(triangles) / seconds);
        out += fmt::format("  \"peak_rss_bytes\": {},\n", PeakRssBytes());
        out += "  \"bad_bricks\": [";
        for (size_t i = 0; i < bad.size(); ++i) {
            out += fmt::format("{}\n    {{\"id\": {}, \"error\": {}}}", i ? "," : "", bad[i].id,
                               JsonString(bad[i].status.ToString()));
        }
        out += bad.empty() ? "]\n}\n" : "\n  ]\n}\n";
        std::fputs(out.c_str(), stdout);
    } else {
        for (const BadBrick& b : bad)
            std::printf("brick %u: %s\n", b.id, b.status.ToString().c_str());
        std::printf(
            "%s: %u of %u bricks intact, %s triangles, %s read in %s (%s triangles/s, %s/s), peak "
            "memory %s\n",
            file.c_str(), brick_count - uint32_t(bad.size()), brick_count,
            FormatCount(double(triangles)).c_str(), FormatBytes(s->bytes_read()).c_str(),
            FormatDuration(seconds).c_str(), FormatCount(double(triangles) / seconds).c_str(),
            FormatBytes(uint64_t(double(s->bytes_read()) / seconds)).c_str(),
            FormatBytes(PeakRssBytes()).c_str());
    }
    std::fflush(stdout);
    if (!bad.empty()) {
        return DataLossError("{}: {} of {} bricks are damaged (first: brick {})", file, bad.size(),
                             brick_count, bad.front().id);
    }
    return Status::Ok();
}

}  // namespace

void RegisterVerifyCommand(CLI::App& app, CommandRun& run) {
    CLI::App* cmd = app.add_subcommand("verify",
                                       "Read every brick of a store, check its checksums and "
                                       "decode it (and its piece of the medium); exit 0 only if "
                                       "all are intact");
    auto file = std::make_shared<std::string>();
    auto json = std::make_shared<bool>(false);
    auto threads = std::make_shared<int>(int(std::max(1u, std::thread::hardware_concurrency())));
    cmd->add_option("FILE", *file, "The .nave store")->required();
    cmd->add_flag("--json", *json, "Print the result as JSON on stdout");
    cmd->add_option("--threads", *threads, "Threads that read and decode bricks")
        ->capture_default_str()
        ->check(CLI::Range(1, 1024));
    cmd->callback([&run, file, json, threads] {
        run = [file, json, threads]() { return Verify(*file, *json, *threads); };
    });
}

}  // namespace nave::cli
