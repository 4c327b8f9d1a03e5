// `nave generate abbey`: writes the procedural abbey as OBJ + MTL, for looking at it in other
// tools. `nave generate dust`: a drifting-dust density grid (.vdb) for a heterogeneous [medium].
// (`nave preprocess --generate abbey:detail=D` builds a store from it directly, without this file.)
#include <chrono>
#include <cstdio>

#include "preprocess/abbey/abbey_source.h"
#include "preprocess/obj_writer.h"
#include "src/cli/commands.h"
#include "src/core/log.h"
#include "src/core/memory.h"
#include "src/core/progress.h"
#include "src/volumes/dust.h"

namespace nave::cli {

void RegisterGenerateCommand(CLI::App& app, CommandRun& run) {
    CLI::App* cmd =
        app.add_subcommand("generate",
                           "Generate a procedural model (the abbey) as OBJ + MTL, or drifting dust "
                           "as an OpenVDB density grid");
    struct Options {
        std::string model = "abbey";
        double detail = 1.0;
        std::string output;
        float voxel_m = 0.25f;
        uint64_t seed = 1;
    };
    auto opt = std::make_shared<Options>();
    cmd->add_option("model", opt->model, "What to generate: abbey, or dust (a .vdb density grid)")
        ->check(CLI::IsMember({"abbey", "dust"}));
    cmd->add_option(
           "--detail", opt->detail,
           "Detail D > 0: about D million triangles (1 = ~1 M; 1000 = ~1 B, see docs/abbey.md)")
        ->check(CLI::Range(1e-4, 1e5));
    cmd->add_option("-o,--output", opt->output,
                    "Output: the abbey's OBJ (an .mtl is written beside it; default abbey.obj), "
                    "the dust's .vdb (default dust.vdb)");
    cmd->add_option("--voxel", opt->voxel_m, "dust: voxel side in metres")
        ->check(CLI::Range(0.01, 100.0));
    cmd->add_option("--seed", opt->seed, "dust: where its puffs are");
    cmd->callback([&run, opt] {
        run = [opt]() -> Status {
            auto start = std::chrono::steady_clock::now();
            if (opt->model == "dust") {
                volumes::DustOptions dust;
                dust.voxel_m = opt->voxel_m;
                dust.seed = opt->seed;
                const std::string output = opt->output.empty() ? "dust.vdb" : opt->output;
                NAVE_RETURN_IF_ERROR(volumes::WriteDriftingDust(output, dust));
                log::Info(
                    "generated {}: drifting dust over the abbey's nave, voxels of {} m, in {}",
                    output, dust.voxel_m,
                    FormatDuration(
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
                            .count()));
                return Status::Ok();
            }
            if (opt->output.empty()) opt->output = "abbey.obj";
            auto source = preprocess::MakeAbbeySource(opt->detail);
            NAVE_ASSIGN_OR_RETURN(auto stats, preprocess::WriteObj(*source, opt->output));
            double seconds =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            log::Info(
                "generated {} (detail {}): {} triangles, {} in {}, {} triangles/s, peak memory {}",
                opt->output, opt->detail, FormatCount(double(stats.triangles)),
                FormatBytes(stats.bytes), FormatDuration(seconds),
                FormatCount(stats.triangles / std::max(seconds, 1e-9)),
                FormatBytes(PeakRssBytes()));
            return Status::Ok();
        };
    });
}

}  // namespace nave::cli
