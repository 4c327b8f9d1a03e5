// `nave render MODEL.nave --config SCENE.toml -o OUT.exr`: spectral rendering with ray streams over
// the bricks of a store. Writes OUT.exr (linear, with settings and statistics as metadata) and
// OUT.png beside it.

#include <cmath>
#include <cstdio>
#include <optional>

#include "cli/commands.h"
#include "cli/interrupt.h"
#include "cli/render_checkpoint.h"
#include "core/file.h"
#include "core/hash.h"
#include "core/log.h"
#include "core/memory.h"
#include "core/progress.h"
#include "core/trace.h"
#include "render/brick_source.h"
#include "render/film.h"
#include "render/integrator.h"
#include "render/pager.h"
#include "render/procedural_scenes.h"
#include "render/scene.h"
#include "render/scene_config.h"
#include "store/store_reader.h"

namespace nave::cli {
namespace {

struct RenderOptions {
    std::string model;
    std::string procedural;
    std::string config;
    std::string output;
    std::optional<int> spp, iterations, threads;
    std::optional<uint64_t> seed, photons, wave_paths;
    std::optional<double> noise, time_limit;
    std::string mode;
    std::string resolution;  // "WxH"
    std::string memory;      // --memory SIZE: page bricks under this budget (docs/pager.md)
    std::string pager;       // --pager TUNABLES
    std::string trace;       // --trace FILE.json
    std::string temp_dir;    // --temp-dir DIR: spill files (default: beside the output)
    bool no_textures = false;
    CheckpointFlags checkpoint;  // --checkpoint, --checkpoint-every, --resume, --stop-after
};

/// Parses "960x640" into width and height.
Status ParseResolution(const std::string& text, int* width, int* height) {
    int w = 0, h = 0;
    char x = 0, extra = 0;
    if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') ||
        w <= 0 || h <= 0 || w > 32768 || h > 32768) {
        return InvalidArgumentError(
            "--resolution {}: expected WIDTHxHEIGHT with each in [1, 32768], as in 960x640", text);
    }
    *width = w;
    *height = h;
    return Status::Ok();
}

std::string ModeName(render::RenderSettings::Mode m) {
    return m == render::RenderSettings::Mode::kPath ? "path" : "photon";
}

/// The most any one brick's load needs beside the brick while it decodes (one decode at a time
/// under --memory).
uint64_t MaxLoadScratchBytes(const render::BrickSource& source) {
    uint64_t most = 0;
    for (uint32_t b = 0; b < source.brick_count(); ++b)
        most = std::max(most, source.LoadScratchBytes(b));
    return most;
}

/// The summary's line on the image's noise: the render's own estimate and what it stopped on.
std::string NoiseLine(const render::RenderSettings& settings, const render::RenderStats& stats) {
    const bool photon = settings.mode == render::RenderSettings::Mode::kPhoton;
    const int done = photon ? stats.iterations : stats.samples_per_pixel;
    std::string line =
        std::isfinite(stats.noise_relmse)
            ? fmt::format("noise: estimated relMSE {:.3g} after {} {}", stats.noise_relmse, done,
                          photon ? "iterations" : "samples per pixel")
            : fmt::format("noise: not estimated (it takes two {})",
                          photon ? "iterations" : "passes");
    if (settings.noise_target > 0) {
        line += std::isfinite(stats.noise_relmse) && stats.noise_relmse <= settings.noise_target
                    ? fmt::format(", target {:.3g} reached", settings.noise_target)
                    : fmt::format(", target {:.3g} not reached (raise --{} or render.time_limit_s)",
                                  settings.noise_target, photon ? "iterations" : "spp");
    }
    if (settings.path_guiding && !photon) {
        line += fmt::format("; path guide: {} cells learning, {} guiding", stats.guide_cells,
                            stats.guide_cells_guiding);
    }
    return line;
}

Status RunRender(const RenderOptions& o) {
    if (o.model.empty() == o.procedural.empty()) {
        return InvalidArgumentError(
            "give either MODEL.nave or --procedural NAME (not both, not neither)");
    }
    std::filesystem::path out = o.output;
    if (out.extension() != ".exr") {
        return InvalidArgumentError(
            "-o {}: the output must end in .exr (the PNG is written beside it)", o.output);
    }
    NAVE_RETURN_IF_ERROR(CheckCheckpointFlags(o.checkpoint));
    NAVE_ASSIGN_OR_RETURN(render::SceneConfig config, render::LoadSceneConfig(o.config));
    if (!o.resolution.empty()) {
        NAVE_RETURN_IF_ERROR(
            ParseResolution(o.resolution, &config.camera.width, &config.camera.height));
    }
    if (o.spp) config.render.spp = *o.spp;
    if (o.iterations) config.render.iterations = *o.iterations;
    if (o.threads) config.render.threads = *o.threads;
    if (o.noise) config.render.noise_target = *o.noise;
    if (o.time_limit) config.render.time_limit_s = *o.time_limit;
    if (o.seed) config.render.seed = *o.seed;
    if (o.photons) config.render.photons_per_iteration = *o.photons;
    if (o.wave_paths) {
        config.render.wave_paths = uint32_t(*o.wave_paths);
        config.render.wave_paths_chosen = true;
    }
    if (o.mode == "path") config.render.mode = render::RenderSettings::Mode::kPath;
    if (o.mode == "photon") config.render.mode = render::RenderSettings::Mode::kPhoton;
    if (o.no_textures) config.textures.enabled = false;
    std::optional<uint64_t> memory_limit;  // --memory, in bytes
    if (!o.memory.empty()) {
        NAVE_ASSIGN_OR_RETURN(uint64_t bytes, ParseByteSize(o.memory));
        memory_limit = bytes;
    }

    // Huge pages for Embree's BVHs: a fresh 4 KiB page costs a fault, and on virtual machines
    // faults took as long as the BVH builds themselves (in-core abbey: 42 s -> 35 s with huge
    // pages).
    NAVE_ASSIGN_OR_RETURN(auto device, render::EmbreeDevice::Create("hugepages=1"));
    std::unique_ptr<render::BrickSource> source;
    uint64_t model_id = 0;  // what a checkpoint of this render must have been written for
    if (!o.model.empty()) {
        NAVE_ASSIGN_OR_RETURN(auto store, render::StoreBrickSource::Open(o.model, device));
        model_id = store->store().header().header_checksum;
        source = std::move(store);
    } else {
        NAVE_ASSIGN_OR_RETURN(source, render::OpenProceduralSource(o.procedural, device));
        const std::string name = "procedural " + o.procedural;
        model_id = Checksum64(name.data(), name.size());
    }
    // Checked before the long work of building the scene: a checkpoint of another render is refused
    // at once.
    NAVE_ASSIGN_OR_RETURN(std::string config_text, ReadFileToString(o.config));
    NAVE_ASSIGN_OR_RETURN(
        std::unique_ptr<PreparedSession> session,
        PrepareSession(
            o.checkpoint,
            RenderIdentity(model_id, o.model.empty() ? "procedural " + o.procedural : o.model,
                           o.config, config_text, config)));
    RemoveStaleRenderTemporaries(out, session->options.checkpoint_path);
    if (session->options.resume != nullptr) {
        log::Info(
            "render: resuming from {} after {} {}", o.checkpoint.resume,
            session->options.resume->done,
            config.render.mode == render::RenderSettings::Mode::kPath ? "passes" : "iterations");
    }
    // Interrupted, a render that writes checkpoints finishes its pass and leaves one to resume
    // from.
    if (session->checkpoints()) session->options.stop_requested = InstallRenderInterruptHandlers();
    NAVE_ASSIGN_OR_RETURN(render::RenderScene scene, render::BuildRenderScene(config, *source));
    // The model's textures, through a capped tile cache (docs/textures.md); only when some material
    // has one, so that untextured models never load OpenImageIO's texture system.
    std::unique_ptr<render::TextureCache> textures;
    const bool any_texture =
        std::any_of(source->materials().begin(), source->materials().end(),
                    [](const store::MaterialRecord& m) { return !m.textures.empty(); });
    if (config.textures.enabled && any_texture) {
        // Its cap: [textures] cache, or under --memory the share [textures] memory_share of the
        // budget, which the pager then counts as reserved (below).
        uint64_t cap = config.textures.cache_bytes;
        if (memory_limit) cap = uint64_t(double(*memory_limit) * config.textures.memory_share);
        NAVE_ASSIGN_OR_RETURN(textures, render::TextureCache::Create(cap));
        std::filesystem::path base = std::filesystem::path(o.model).parent_path();
        std::vector<std::string> warnings;
        NAVE_RETURN_IF_ERROR(render::AttachTextures(config, base.empty() ? "." : base, *textures,
                                                    &scene, &warnings));
        for (const std::string& w : warnings) log::Warning("{}", w);
        // A cap above what all the textures take decoded buys nothing and, under --memory, would
        // only take room from the bricks. Twice what they take leaves room for the cache's own
        // bookkeeping and for tiles in flight.
        const uint64_t enough = 2 * textures->opened_pixel_bytes() + (uint64_t(4) << 20);
        if (enough < textures->max_memory_bytes())
            NAVE_RETURN_IF_ERROR(textures->SetMaxMemoryBytes(enough));
    }
    log::Info("render: {} bricks, {} materials, {}x{}, mode {}{}", source->brick_count(),
              scene.materials.size(), config.camera.width, config.camera.height,
              ModeName(config.render.mode),
              scene.sun >= 0 ? ", sun " + scene.sun_description : std::string());

    // --memory covers the resident bricks plus a reserve for the rest (film, ray queues, process);
    // the bricks get what is left (docs/pager.md).
    render::PagerOptions options;
    NAVE_RETURN_IF_ERROR(render::ParsePagerTunables(o.pager, &options).WithContext("--pager"));
    std::unique_ptr<TraceRecorder> trace;
    if (!o.trace.empty()) {
        trace = std::make_unique<TraceRecorder>();
        options.trace = trace.get();
    }
    options.spill_dir = !o.temp_dir.empty() ? std::filesystem::path(o.temp_dir) : out.parent_path();
    // The brick sizes below depend on how their BVHs are built.
    NAVE_RETURN_IF_ERROR(source->SetBvhSettings(options.bvh));
    if (memory_limit) {
        const uint64_t memory = *memory_limit;
        // The texture cache's cap comes out of --memory too (docs/pager.md).
        const uint64_t texture_bytes = textures ? textures->max_memory_bytes() : 0;
        // Queues beyond a small share of the budget spill to disk.
        if (options.queue_memory_bytes == render::PagerOptions::kAutoQueueMemory) {
            options.queue_memory_bytes = render::QueueMemoryBytes(memory);
        }
        const render::BrickBudgetMinimum need =
            render::MinimumBrickBudget(*source, options.prefetch);
        // Writing a checkpoint holds the film's and the guide's state beside them.
        const uint64_t checkpoint_bytes =
            session->checkpoints() ? render::CheckpointMemoryBytes(
                                         config.render, config.camera.width, config.camera.height,
                                         config.output.aov_albedo || config.output.aov_normal ||
                                             config.output.aov_depth)
                                   : 0;
        auto reserve_for = [&](const render::RenderSettings& settings) {
            return render::RenderReserveBytes(settings, config.camera.width, config.camera.height,
                                              source->brick_count(), options.wave_overlap,
                                              CurrentRssBytes(), options.queue_memory_bytes) +
                   texture_bytes + MaxLoadScratchBytes(*source) + checkpoint_bytes;
        };
        uint64_t reserve = reserve_for(scene.settings);
        // When the bricks will not all fit, one wave for the whole image unless the user chose
        // (WavePathsUnderPaging): its camera rays spill to disk as they are generated.
        if (options.queue_memory_bytes > 0 && memory < reserve + need.total_bytes) {
            const uint32_t wave = render::WavePathsUnderPaging(scene.settings, config.camera.width,
                                                               config.camera.height);
            if (wave != scene.settings.wave_paths) {
                scene.settings.wave_paths = wave;
                reserve = reserve_for(scene.settings);
                log::Info(
                    "render: waves of {} camera paths (--wave-paths); their rays beyond {} of "
                    "queues spill "
                    "to disk",
                    wave, FormatBytes(options.queue_memory_bytes));
            }
        }
        // The image is written after the bricks are freed, but OpenImageIO must fit then (unless
        // the texture cache loaded it already: the process's size counts it then).
        const uint64_t writer =
            CurrentRssBytes() + (textures ? 0 : render::kImageWriterBytes) +
            render::Film::MemoryBytes(config.camera.width, config.camera.height);
        const uint64_t minimum = std::max(reserve + need.min_bytes, writer);
        if (memory < minimum) {
            return ResourceExhaustedError(
                "--memory {} ({} bytes) is too small for this model: {}, the reserve for the film, "
                "ray queues "
                "and process is {} ({} bytes){}, and writing the image afterwards takes {} ({} "
                "bytes, "
                "OpenImageIO included): at least {} ({} bytes) is needed (all {} bricks resident "
                "at once take "
                "{}, {} bytes)",
                o.memory, memory, need.DescribeLargest(options.prefetch), FormatBytes(reserve),
                reserve,
                texture_bytes > 0
                    ? fmt::format(", of which {} for the texture cache", FormatBytes(texture_bytes))
                    : std::string(),
                FormatBytes(writer), writer, FormatBytes(minimum), minimum, source->brick_count(),
                FormatBytes(need.total_bytes), need.total_bytes);
        }
        options.brick_budget_bytes = memory - reserve;
        if (options.in_core()) --options.brick_budget_bytes;
        options.process_memory_bytes = memory;
        log::Info(
            "render: --memory {}: {} for bricks ({} for all {} bricks at once, {} bytes), {} ({} "
            "bytes) "
            "reserved{}",
            FormatBytes(memory), FormatBytes(options.brick_budget_bytes),
            FormatBytes(need.total_bytes), source->brick_count(), need.total_bytes,
            FormatBytes(reserve), reserve,
            texture_bytes > 0
                ? fmt::format(", of which {} for the texture cache", FormatBytes(texture_bytes))
                : std::string());
    }

    render::Film film(config.camera.width, config.camera.height, scene.output);
    render::RenderStats stats;
    NAVE_RETURN_IF_ERROR(
        render::RenderStreams(scene, &film, &stats, {}, &options, &session->options));
    const bool photon = config.render.mode == render::RenderSettings::Mode::kPhoton;
    const int done = photon ? stats.iterations : stats.samples_per_pixel;
    const int asked = photon ? config.render.iterations : config.render.spp;
    if (session->options.stop_requested != nullptr && session->options.stop_requested->load() &&
        done < asked) {
        // Stopped early, no image: the output is either absent, the previous one, or a complete
        // render (a signal during the last pass does not cost the image).
        return Status(
            StatusCode::kCancelled,
            fmt::format("interrupted after {} {}: {} not written; the checkpoint {} continues it "
                        "(--resume {})",
                        done, photon ? "iterations" : "passes", out.string(),
                        session->options.checkpoint_path.string(),
                        session->options.checkpoint_path.string()));
    }
    // Free the bricks and the queues' pages before the image writer loads OpenImageIO (~120 MiB),
    // so that the two never add up (the allocator keeps freed pages a while otherwise).
    for (uint32_t b = 0; b < source->brick_count(); ++b) source->Evict(b);
    ReturnFreeMemory();

    const uint64_t rays = stats.rays;
    const double secs = std::max(1e-9, stats.wall_seconds);
    std::string settings = fmt::format(
        "mode={} spp={} iterations={} photons_per_iteration={} seed={} max_depth={} threads={} "
        "noise_target={} "
        "time_limit_s={}",
        ModeName(config.render.mode), stats.samples_per_pixel, stats.iterations,
        config.render.photons_per_iteration, config.render.seed, config.render.max_depth,
        config.render.threads, config.render.noise_target, config.render.time_limit_s);
    std::string statistics = fmt::format(
        "wall={:.3f}s rays={} segments={} shadow_segments={} photons={} brick_moves={} "
        "batches={} brick_loads={} bytes_read={} peak_rss={} brick_budget={} "
        "peak_brick_bytes={} brick_evictions={} brick_reloads={} prefetch_loads={} "
        "resident_hits={} stall={:.3f}s brick_cache_reads={} brick_cache_disk_bytes={} "
        "spilled_rays={} spill_bytes_written={} memory_returns={} noise_relmse={:.6g}",
        stats.wall_seconds, stats.rays, stats.segments_traced, stats.shadow_segments, stats.photons,
        stats.brick_moves, stats.batches, stats.residency.loads, stats.bytes_read,
        stats.peak_rss_bytes,
        stats.residency.brick_budget_bytes > 0 ? std::to_string(stats.residency.brick_budget_bytes)
                                               : std::string("in-core"),
        stats.residency.peak_resident_bytes, stats.residency.evictions, stats.residency.reloads,
        stats.residency.prefetch_loads, stats.residency.resident_hits,
        stats.residency.stall_seconds, stats.cache_reads, stats.cache_disk_bytes,
        stats.spilled_rays, stats.spill_bytes_written, stats.residency.memory_returns,
        stats.noise_relmse);
    std::vector<std::pair<std::string, std::string>> metadata = {
        {"Software", std::string("nave ") + NAVE_VERSION},
        {"nave:model", o.model.empty() ? "procedural " + o.procedural : o.model},
        {"nave:config", o.config},
        {"nave:settings", settings},
        {"nave:statistics", statistics},
    };
    if (scene.sun >= 0) metadata.push_back({"nave:sun", scene.sun_description});
    if (textures) {
        metadata.push_back(
            {"nave:textures", fmt::format("cache_cap={} bytes_read={}",
                                          textures->max_memory_bytes(), textures->bytes_read())});
    }
    NAVE_RETURN_IF_ERROR(film.Write(out, metadata));
    if (trace) NAVE_RETURN_IF_ERROR(trace->Write(o.trace).WithContext("--trace"));

    if (log::GetLevel() > log::Level::kInfo) return Status::Ok();  // -q: errors only, no summary
    // The whole process's peak, image writing included: what --memory bounds.
    const uint64_t process_peak = PeakRssBytes();
    std::filesystem::path png = out;
    png.replace_extension(".png");
    std::fprintf(
        stderr,
        "nave render: wrote %s and %s\n"
        "  time %s, %s rays/s (%s rays: %s segments traced, %s shadow segments), %s photons/s\n"
        "  rays moved between bricks %s, brick visits %s, loads %s, read %s, peak memory %s (%llu "
        "bytes), peak queues %s\n",
        out.string().c_str(), png.string().c_str(), FormatDuration(stats.wall_seconds).c_str(),
        FormatCount(double(rays) / secs).c_str(), FormatCount(double(rays)).c_str(),
        FormatCount(double(stats.segments_traced)).c_str(),
        FormatCount(double(stats.shadow_segments)).c_str(),
        FormatCount(double(stats.photons) / secs).c_str(),
        FormatCount(double(stats.brick_moves)).c_str(), FormatCount(double(stats.batches)).c_str(),
        FormatCount(double(stats.residency.loads)).c_str(), FormatBytes(stats.bytes_read).c_str(),
        FormatBytes(process_peak).c_str(), static_cast<unsigned long long>(process_peak),
        FormatBytes(stats.peak_queue_bytes).c_str());
    std::fprintf(stderr, "  %s\n", NoiseLine(config.render, stats).c_str());
    std::fprintf(stderr,
                 "  bricks: %s, peak resident %s%s, evictions %s, reloads %s, prefetched %s, "
                 "resident when needed %s of %s, workers stalled on loads %s%s\n",
                 memory_limit ? ("budget " + FormatBytes(stats.residency.brick_budget_bytes) +
                                 " (--memory " + o.memory + ")")
                                    .c_str()
                              : "in-core",
                 FormatBytes(stats.residency.peak_resident_bytes).c_str(),
                 memory_limit ? fmt::format(" ({:.0f}% of budget)",
                                            100.0 * double(stats.residency.peak_resident_bytes) /
                                                double(stats.residency.brick_budget_bytes))
                                    .c_str()
                              : "",
                 FormatCount(double(stats.residency.evictions)).c_str(),
                 FormatCount(double(stats.residency.reloads)).c_str(),
                 FormatCount(double(stats.residency.prefetch_loads)).c_str(),
                 FormatCount(double(stats.residency.resident_hits)).c_str(),
                 FormatCount(double(stats.residency.acquires)).c_str(),
                 FormatDuration(stats.residency.stall_seconds).c_str(),
                 stats.residency.memory_returns > 0
                     ? fmt::format(", free pages given back {} times near --memory",
                                   stats.residency.memory_returns)
                           .c_str()
                     : "");
    if (stats.spilled_rays > 0) {
        std::fprintf(
            stderr,
            "  ray queues: %s rays spilled to disk (%s written, at most %s on disk at once)\n",
            FormatCount(double(stats.spilled_rays)).c_str(),
            FormatBytes(stats.spill_bytes_written).c_str(),
            FormatBytes(stats.spill_peak_disk_bytes).c_str());
    }
    if (stats.cache_bricks_written > 0) {
        std::fprintf(stderr,
                     "  brick cache: %s bricks decoded once, %s reloads read back, %s on disk (%s "
                     "decoded)\n",
                     FormatCount(double(stats.cache_bricks_written)).c_str(),
                     FormatCount(double(stats.cache_reads)).c_str(),
                     FormatBytes(stats.cache_disk_bytes).c_str(),
                     FormatBytes(stats.cache_mesh_bytes).c_str());
    }
    if (textures) {
        std::fprintf(stderr, "  textures: read %s through a %s tile cache (%s held at the end)\n",
                     FormatBytes(textures->bytes_read()).c_str(),
                     FormatBytes(textures->max_memory_bytes()).c_str(),
                     FormatBytes(textures->memory_used_bytes()).c_str());
    }
    return Status::Ok();
}

}  // namespace

void RegisterRenderCommand(CLI::App& app, CommandRun& run) {
    auto opts = std::make_shared<RenderOptions>();
    CLI::App* cmd = app.add_subcommand(
        "render",
        "Render a brick store with spectral ray streams over its bricks (path tracing or SPPM)");
    cmd->add_option("model", opts->model, "The model (.nave store from `nave preprocess`)");
    cmd->add_option("--procedural", opts->procedural,
                    "Render a built-in test model instead: furnace, caustic or clutter, with "
                    ":bricks=N for N^3 bricks");
    cmd->add_option("-c,--config", opts->config, "Scene config (TOML; keys in configs/README.md)")
        ->required();
    cmd->add_option("-o,--output", opts->output,
                    "Output OpenEXR file; a tone-mapped PNG is written beside it")
        ->required();
    cmd->add_option("--resolution", opts->resolution,
                    "Override camera.resolution, as WIDTHxHEIGHT (e.g. 960x640)");
    cmd->add_option("--spp", opts->spp, "Override render.spp")->check(CLI::PositiveNumber);
    cmd->add_option("--iterations", opts->iterations, "Override render.iterations")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--noise", opts->noise,
                    "Override render.noise_target: stop once the estimated relMSE of the image is "
                    "at most this "
                    "(docs/render.md, \"Noise\"); --spp / --iterations are then the most it does")
        ->check(CLI::Range(0.0, 100.0));
    cmd->add_option("--time-limit", opts->time_limit,
                    "Override render.time_limit_s (seconds; 0: none)")
        ->check(CLI::Range(0.0, 1e7));
    cmd->add_option("--photons", opts->photons,
                    "Override render.photons_per_iteration (at most 4294967295)")
        ->check(CLI::Range(uint64_t(1), uint64_t(UINT32_MAX)));
    cmd->add_option("--threads", opts->threads, "Override render.threads (0: all cores)")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--seed", opts->seed, "Override render.seed");
    cmd->add_option("--mode", opts->mode, "Override render.mode")
        ->check(CLI::IsMember({"path", "photon"}));
    cmd->add_option("--wave-paths", opts->wave_paths,
                    "Camera paths (or photons) in flight at once (default 1048576; under --memory, "
                    "when the bricks do "
                    "not all fit, the whole image in path mode): more rays per brick visit, so "
                    "fewer loads, for "
                    "more ray-queue memory or spilling")
        ->check(CLI::Range(uint64_t(1024), uint64_t(1) << 31));
    cmd->add_option("--memory", opts->memory,
                    "Memory budget (e.g. 2G, 300M): bricks are paged in and out to stay within it "
                    "(docs/pager.md). "
                    "Default: every brick stays resident once loaded");
    cmd->add_option(
        "--pager", opts->pager,
        "Pager tunables, comma separated (docs/pager.md): " + std::string(render::kPagerTunables));
    cmd->add_option(
        "--temp-dir", opts->temp_dir,
        "Where spill files go under --memory (the brick cache; docs/pager.md). They have no name "
        "and vanish when nave exits. Default: beside the output");
    cmd->add_option(
        "--trace", opts->trace,
        "Write a timeline of the render's loads, evictions, stalls, batches and memory as Chrome "
        "trace events (JSON for ui.perfetto.dev or chrome://tracing; docs/pager.md)");
    cmd->add_flag("--no-textures", opts->no_textures,
                  "Ignore the model's textures (textures.enabled = false)");
    cmd->add_option("--checkpoint", opts->checkpoint.checkpoint,
                    "Write the render's state to FILE between passes (photon mode: iterations), at "
                    "most every "
                    "--checkpoint-every and after the last, so that --resume FILE continues it "
                    "after a crash "
                    "or "
                    "an interruption (SIGINT/SIGTERM: finish the pass, write FILE, exit). Every "
                    "pass then ends "
                    "with all its rays traced (docs/render.md, \"Checkpoints\")")
        ->type_name("FILE");
    cmd->add_option(
           "--checkpoint-every", opts->checkpoint.checkpoint_every,
           "Least time between two checkpoints, as 90s, 10m, 1.5h or 2d (0: after every pass or "
           "iteration). Default 10m")
        ->type_name("DURATION");
    cmd->add_option(
           "--resume", opts->checkpoint.resume,
           "Continue the render whose checkpoint is FILE: same model, config, --resolution, "
           "--seed, "
           "--photons, --mode and nave version, else refused; --spp / --iterations may be raised. "
           "Checkpoints go on to FILE unless --checkpoint names another")
        ->type_name("FILE");
    cmd->add_option("--stop-after", opts->checkpoint.stop_after,
                    "End this run after N passes (photon mode: iterations) of its own, writing the "
                    "image so far "
                    "and the checkpoint: a long render in several sittings")
        ->check(CLI::PositiveNumber);
    cmd->callback([&run, opts] { run = [opts] { return RunRender(*opts); }; });
}

}  // namespace nave::cli
