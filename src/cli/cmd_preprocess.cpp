// `nave preprocess`: model files (or the procedural abbey), and a medium's grid, -> a brick store,
// in bounded memory.
// The library plans and runs; what touches the whole process is done here: the handlers of SIGINT
// and SIGTERM (src/cli/interrupt.h) and the open-file limit.
#include <sys/resource.h>

#include <cstdio>

#include "preprocess/import/cad_plugin.h"
#include "preprocess/import/ifc_plugin.h"
#include "preprocess/preprocess.h"
#include "src/cli/commands.h"
#include "src/cli/interrupt.h"
#include "src/core/log.h"
#include "src/core/memory.h"

namespace nave::cli {
namespace {

// Each leaf of a split pass is an open file: the soft limit (often 1024) would cap the pass's
// fan-out (preprocess::MaxSplitFanout) where the hard limit does not.
void RaiseOpenFileLimit() {
    rlimit files{};
    if (getrlimit(RLIMIT_NOFILE, &files) != 0 || files.rlim_cur >= files.rlim_max) return;
    files.rlim_cur = files.rlim_max;
    setrlimit(RLIMIT_NOFILE, &files);
}

}  // namespace

void RegisterPreprocessCommand(CLI::App& app, CommandRun& run) {
    CLI::App* cmd = app.add_subcommand(
        "preprocess",
        "Cut models (OBJ, PLY, STL, glTF, STEP, IGES, IFC, DXF, Assimp formats), and a medium's "
        "density (OpenVDB), into a brick store (.nave)");
    // Which readers this build has: STEP/IGES and IFC are optional at build time.
    cmd->footer(fmt::format(
        "Formats: .obj .ply .stl .gltf .glb (nave); .step .stp .iges .igs (Open CASCADE: {}); .ifc "
        "(IFC++: {}); .dxf .fbx .dae .3ds .off ... (Assimp); .dwg is refused (export DXF). "
        "docs/preprocess.md, \"Formats\".",
        preprocess::CadPluginBuilt() ? "on" : "off in this build",
        preprocess::IfcPluginBuilt() ? "on" : "off in this build, .ifc goes to Assimp"));
    struct Options {
        std::vector<std::string> inputs;
        std::string generate, output, memory, temp_dir;
        std::string medium_grid = preprocess::PreprocessOptions{}.medium_grid;
        uint64_t brick_triangles = 0;
        double precision = 0;
        int threads = 0;
        int draco_speed = store::EncodeOptions{}.draco_speed;
        double derived_normal_error = store::EncodeOptions{}.derived_normal_error_deg;
        uint32_t verify_every = 8;
        bool no_textures = false;
        std::vector<double> level_errors;
        bool levels = false;
    };
    auto opt = std::make_shared<Options>();
    cmd->add_option("inputs", opt->inputs,
                    "Model files, several merged into one model; and at most one OpenVDB file "
                    "(.vdb), a medium's density in the model's units, cut along the bricks");
    cmd->add_option("--medium-grid", opt->medium_grid,
                    "The float grid of the .vdb file that holds the medium's density")
        ->capture_default_str();
    cmd->add_option("--generate", opt->generate,
                    "Use a generator instead of files: abbey or abbey:detail=D");
    cmd->add_option("-o,--output", opt->output, "Output store (.nave)")->required();
    cmd->add_option("--memory", opt->memory,
                    "Memory budget, e.g. 4G (default: a quarter of physical memory)");
    cmd->add_option("--brick-triangles", opt->brick_triangles,
                    "Target triangles per brick (default 700000, or fewer when --memory cannot "
                    "hold the encoding work of a brick that size)");
    cmd->add_option(
        "--precision", opt->precision,
        "Grid step in model units (default: bounds diagonal / 2^20; max error step * sqrt(3) / 2)");
    cmd->add_option("--threads", opt->threads, "Threads (default: all hardware threads)");
    cmd->add_option("--temp-dir", opt->temp_dir,
                    "Where to put temporary files (default: beside the output)");
    cmd->add_option("--draco-speed", opt->draco_speed,
                    "Draco encoder speed 0 (smallest) .. 10 (fastest)")
        ->check(CLI::Range(0, 10));
    cmd->add_option(
           "--derived-normal-error", opt->derived_normal_error,
           "Degrees: smooth faces whose normals the renderer can recompute from the positions "
           "within this angle store none (default 3; 0 stores them all, for mirror-like "
           "materials)")
        ->check(CLI::Range(0.0, 10.0));
    cmd->add_option("--verify-every", opt->verify_every,
                    "Decode every N-th brick (and the first) again after encoding to check it; 1 "
                    "checks all (a third slower), 0 none (default 8; `nave verify` checks a store "
                    "whole)");
    cmd->add_flag("--levels", opt->levels,
                  "Store coarser levels of detail beside each brick, for `nave render` with "
                  "render.lod = \"auto\" (docs/render.md, \"Levels of detail\": not yet free of "
                  "bias, so not made by default)");
    cmd->add_option("--level-errors", opt->level_errors,
                    "With --levels: the error each level aims at, as fractions of its brick's "
                    "extent, finest first (default 0.001,0.004)")
        ->delimiter(',');
    cmd->add_flag(
        "--no-textures", opt->no_textures,
        "Do not convert textures (the store's materials keep their flat colours; OpenImageIO, "
        "~160 MB, is then never loaded)");
    cmd->callback([&run, opt] {
        run = [opt]() -> Status {
            preprocess::PreprocessOptions o;
            for (const auto& in : opt->inputs) o.inputs.emplace_back(in);
            o.generate = opt->generate;
            o.medium_grid = opt->medium_grid;
            o.output = opt->output;
            if (!opt->memory.empty()) {
                NAVE_ASSIGN_OR_RETURN(o.memory_bytes, ParseByteSize(opt->memory));
            }
            o.brick_triangles = opt->brick_triangles;
            o.precision = opt->precision;
            o.threads = opt->threads;
            o.temp_dir = opt->temp_dir;
            o.encode.draco_speed = opt->draco_speed;
            o.encode.derived_normal_error_deg = opt->derived_normal_error;
            o.verify_every = opt->verify_every;
            if (!opt->level_errors.empty() && !opt->levels) {
                return InvalidArgumentError("--level-errors is given without --levels");
            }
            if (opt->levels) {
                o.encode.levels.relative_errors = opt->level_errors.empty()
                                                      ? store::LevelOptions{}.relative_errors
                                                      : opt->level_errors;
            }
            o.convert_textures = !opt->no_textures;
            o.tool_version = std::string("nave ") + NAVE_VERSION;
            // The first signal asks the run to unwind (removing its files); a second stops it now.
            o.interrupt = InstallInterruptHandlers();
            RaiseOpenFileLimit();
            NAVE_ASSIGN_OR_RETURN(auto stats, preprocess::RunPreprocess(o));
            log::Info("wrote {}\n{}", o.output.string(), preprocess::FormatSummary(stats));
            return Status::Ok();
        };
    });
}

}  // namespace nave::cli
