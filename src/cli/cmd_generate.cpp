// `nave generate abbey`: writes the procedural abbey as OBJ + MTL, for looking at it in other
// tools.
// (`nave preprocess --generate abbey:detail=D` builds a store from it directly, without this file.)
#include <chrono>
#include <cstdio>

#include "preprocess/abbey/abbey_source.h"
#include "preprocess/obj_writer.h"
#include "src/cli/commands.h"
#include "src/core/log.h"
#include "src/core/memory.h"
#include "src/core/progress.h"

namespace nave::cli {

void RegisterGenerateCommand(CLI::App& app, CommandRun& run) {
    CLI::App* cmd =
        app.add_subcommand("generate", "Generate a procedural model (the abbey) as OBJ + MTL");
    struct Options {
        std::string model = "abbey";
        double detail = 1.0;
        std::string output = "abbey.obj";
    };
    auto opt = std::make_shared<Options>();
    cmd->add_option("model", opt->model, "What to generate: abbey")
        ->check(CLI::IsMember({"abbey"}));
    cmd->add_option(
           "--detail", opt->detail,
           "Detail D > 0: about D million triangles (1 = ~1 M; 1000 = ~1 B, see docs/abbey.md)")
        ->check(CLI::Range(1e-4, 1e5));
    cmd->add_option("-o,--output", opt->output, "Output OBJ file (an .mtl is written beside it)");
    cmd->callback([&run, opt] {
        run = [opt]() -> Status {
            auto start = std::chrono::steady_clock::now();
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
