// `nave render MODEL.nave --config SCENE.toml -o OUT.exr`: spectral rendering with ray streams over
// the bricks of a store. Writes OUT.exr (linear, with settings and statistics as metadata) and
// OUT.png beside it.

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <optional>

#include "src/cli/commands.h"
#include "src/cli/distributed.h"
#include "src/cli/interrupt.h"
#include "src/cli/render_checkpoint.h"
#include "src/core/duration.h"
#include "src/core/file.h"
#include "src/core/hash.h"
#include "src/core/log.h"
#include "src/core/memory.h"
#include "src/core/trace.h"
#include "src/render/bricks/brick_source.h"
#include "src/render/bricks/procedural_scenes.h"
#include "src/render/bricks/store_brick_source.h"
#include "src/render/film/film.h"
#include "src/render/integrators/render_memory.h"
#include "src/render/integrators/render_streams.h"
#include "src/render/integrators/render_summary.h"
#include "src/render/scene/scene.h"
#include "src/render/scene/scene_config.h"
#include "src/render/stream/memory_plan.h"
#include "src/render/stream/pager.h"
#include "src/render/transport/visible_points.h"
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
    std::string rank_timeout = "10m";  // --rank-timeout: under mpirun, the longest wait for rays
    std::string pack_rays = "on";      // --pack-rays: under mpirun, LZ4 on the rays sent
    std::string coarse_levels_everywhere = "on";  // --coarse-levels-everywhere: under mpirun
    bool no_textures = false;
    std::string lod;
    bool no_lod = false;         // --no-lod: --lod full
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

/// What can be checked of the options before anything is read.
Status CheckOptions(const RenderOptions& o) {
    if (o.model.empty() == o.procedural.empty()) {
        return InvalidArgumentError(
            "give either MODEL.nave or --procedural NAME (not both, not neither)");
    }
    if (std::filesystem::path(o.output).extension() != ".exr") {
        return InvalidArgumentError(
            "-o {}: the output must end in .exr (the PNG is written beside it)", o.output);
    }
    return CheckCheckpointFlags(o.checkpoint);
}

/// The scene config of `o.config` with the command line's overrides.
StatusOr<render::SceneConfig> BuildConfig(const RenderOptions& o) {
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
    if (o.lod == "auto") config.render.lod = render::RenderSettings::Lod::kAuto;
    if (o.lod == "full" || o.no_lod) config.render.lod = render::RenderSettings::Lod::kFull;
    return config;
}

/// The model to render and what a checkpoint of its render must have been written for.
struct OpenedModel {
    std::unique_ptr<render::BrickSource> source;
    uint64_t id = 0;
    std::string name;  ///< the store's path, or "procedural NAME"
};

StatusOr<OpenedModel> OpenModel(const RenderOptions& o,
                                const std::shared_ptr<render::EmbreeDevice>& device) {
    OpenedModel model;
    if (!o.model.empty()) {
        NAVE_ASSIGN_OR_RETURN(auto store, render::StoreBrickSource::Open(o.model, device));
        model.id = store->store().header().header_checksum;
        model.name = o.model;
        model.source = std::move(store);
    } else {
        NAVE_ASSIGN_OR_RETURN(model.source, render::OpenProceduralSource(o.procedural, device));
        model.name = "procedural " + o.procedural;
        model.id = Checksum64(model.name.data(), model.name.size());
    }
    return model;
}

/// The model's textures attached to `scene` through a capped tile cache (docs/textures.md); null
/// when textures are off or no material has one, so that untextured models never load
/// OpenImageIO's texture system.
StatusOr<std::unique_ptr<render::TextureCache>> AttachModelTextures(
    const RenderOptions& o, const render::SceneConfig& config, const render::BrickSource& source,
    std::optional<uint64_t> memory_bytes, render::RenderScene* scene) {
    const bool any_texture =
        std::any_of(source.materials().begin(), source.materials().end(),
                    [](const store::MaterialRecord& m) { return !m.textures.empty(); });
    if (!config.textures.enabled || !any_texture) return std::unique_ptr<render::TextureCache>();
    NAVE_ASSIGN_OR_RETURN(
        std::unique_ptr<render::TextureCache> textures,
        render::TextureCache::Create(render::TextureCacheCapBytes(config.textures, memory_bytes)));
    std::filesystem::path base = std::filesystem::path(o.model).parent_path();
    std::vector<std::string> warnings;
    NAVE_RETURN_IF_ERROR(
        render::AttachTextures(config, base.empty() ? "." : base, *textures, scene, &warnings));
    for (const std::string& w : warnings) log::Warning("{}", w);
    const uint64_t enough = render::TextureCacheEnoughBytes(textures->opened_pixel_bytes());
    if (enough < textures->max_memory_bytes())
        NAVE_RETURN_IF_ERROR(textures->SetMaxMemoryBytes(enough));
    return textures;
}

/// The pager's tunables from --pager, its trace (--trace: into `trace`) and its spill directory
/// (--temp-dir, else beside `out`).
StatusOr<render::PagerOptions> BuildPagerOptions(const RenderOptions& o,
                                                 const std::filesystem::path& out,
                                                 TraceRecorder* trace) {
    render::PagerOptions options;
    NAVE_RETURN_IF_ERROR(render::ParsePagerTunables(o.pager, &options).WithContext("--pager"));
    options.trace = trace;
    options.spill_dir = !o.temp_dir.empty() ? std::filesystem::path(o.temp_dir) : out.parent_path();
    return options;
}

/// Splits --memory (render::RenderMemoryPlan) and hands the split to `pager` and `scene`.
Status PlanMemory(const RenderOptions& o, uint64_t memory_bytes, const render::SceneConfig& config,
                  const render::BrickSource& source, const render::TextureCache* textures,
                  bool checkpoints, render::PagerOptions* pager, render::RenderScene* scene) {
    render::RenderMemoryInputs inputs = render::RenderMemoryInputs::Measure(source, *pager);
    inputs.memory_bytes = memory_bytes;
    inputs.memory_text = o.memory;
    inputs.settings = scene->settings;
    inputs.width = config.camera.width;
    inputs.height = config.camera.height;
    inputs.state = render::RenderStateMemory(
        scene->settings, config.camera.width, config.camera.height,
        config.output.aov_albedo || config.output.aov_normal || config.output.aov_depth,
        checkpoints, render::UsesCausticPoints(scene->settings, scene->materials));
    inputs.texture_cache_bytes = textures ? textures->max_memory_bytes() : 0;
    inputs.image_library_loaded = textures != nullptr;
    NAVE_ASSIGN_OR_RETURN(render::RenderMemoryPlan plan, render::RenderMemoryPlan::Make(inputs));
    plan.Apply(pager, &scene->settings);
    if (plan.chose_wave_paths()) log::Info("render: {}", plan.DescribeWaves());
    log::Info("render: {}", plan.Describe());
    return Status::Ok();
}

/// Reads and checks --resume against this render, removes temporaries of killed renders and, when
/// the render writes checkpoints, catches SIGINT and SIGTERM so that an interrupted render finishes
/// its pass and leaves a checkpoint to resume from. Before the long work of building the scene: a
/// checkpoint of another render is refused at once.
StatusOr<std::unique_ptr<PreparedSession>> StartSession(const RenderOptions& o,
                                                        const OpenedModel& model,
                                                        const render::SceneConfig& config,
                                                        const std::filesystem::path& out) {
    NAVE_ASSIGN_OR_RETURN(std::string config_text, ReadFileToString(o.config));
    NAVE_ASSIGN_OR_RETURN(
        std::unique_ptr<PreparedSession> session,
        PrepareSession(o.checkpoint,
                       RenderIdentity(model.id, model.name, o.config, config_text, config)));
    RemoveStaleRenderTemporaries(out, session->options.checkpoint_path);
    if (session->options.resume != nullptr) {
        log::Info(
            "render: resuming from {} after {} {}", o.checkpoint.resume,
            session->options.resume->done,
            config.render.mode == render::RenderSettings::Mode::kPath ? "passes" : "iterations");
    }
    if (session->checkpoints()) session->options.stop_requested = InstallRenderInterruptHandlers();
    return session;
}

/// Cancelled when a signal ended the run before all its passes (or iterations): no image then,
/// the output is either absent, the previous one, or a complete render (a signal during the last
/// pass does not cost the image).
Status CheckNotInterrupted(const PreparedSession& session, const render::RenderSettings& asked,
                           const render::RenderStats& stats, const std::filesystem::path& out) {
    const bool photon = asked.mode == render::RenderSettings::Mode::kPhoton;
    const int done = photon ? stats.iterations : stats.samples_per_pixel;
    const int wanted = photon ? asked.iterations : asked.spp;
    const std::atomic<bool>* stop = session.options.stop_requested;
    if (stop == nullptr || !stop->load() || done >= wanted) return Status::Ok();
    const std::string checkpoint = session.options.checkpoint_path.string();
    return Status(
        StatusCode::kCancelled,
        fmt::format("interrupted after {} {}: {} not written; the checkpoint {} "
                    "continues it (--resume {})",
                    done, photon ? "iterations" : "passes", out.string(), checkpoint, checkpoint));
}

/// What the summary reports of the texture cache, if the render had one.
std::optional<render::TextureCacheFacts> TextureFacts(const render::TextureCache* textures) {
    if (textures == nullptr) return std::nullopt;
    return render::TextureCacheFacts{textures->max_memory_bytes(), textures->bytes_read(),
                                     textures->memory_used_bytes()};
}

/// Writes the image (OUT.exr and the PNG beside it) with the render's settings and statistics as
/// metadata.
Status WriteImage(const RenderOptions& o, const OpenedModel& model,
                  const std::filesystem::path& out, const render::RenderScene& scene,
                  const render::Film& film, const render::RenderSummary& summary) {
    std::vector<std::pair<std::string, std::string>> metadata = {
        {"Software", std::string("nave ") + NAVE_VERSION},
        {"nave:model", model.name},
        {"nave:config", o.config},
        {"nave:settings", summary.SettingsText()},
        {std::string(render::kStatisticsAttribute),
         summary.MetadataText(render::kStatisticsAttribute)},
    };
    if (scene.sun >= 0) metadata.push_back({"nave:sun", scene.sun_description});
    const std::string textures = summary.MetadataText(render::kTexturesAttribute);
    if (!textures.empty()) metadata.push_back({std::string(render::kTexturesAttribute), textures});
    return film.Write(out, metadata);
}

/// The summary on the terminal, after the image is written (unless -q).
void PrintSummary(const RenderOptions& o, const std::filesystem::path& out,
                  render::RenderSummary* summary) {
    if (log::GetLevel() > log::Level::kInfo) return;  // -q: errors only, no summary
    // The whole process's peak, image writing included: what --memory bounds.
    summary->RecordProcessPeak(PeakRssBytes());
    std::string text = fmt::format("nave render: wrote {} and {}\n", out.string(),
                                   render::Film::DisplayPathOf(out).string());
    for (const std::string& line : summary->TerminalLines(o.memory)) text += "  " + line + "\n";
    std::fputs(text.c_str(), stderr);
}

Status RunRender(const RenderOptions& o) {
    NAVE_RETURN_IF_ERROR(CheckOptions(o));
    const std::filesystem::path out = o.output;
    NAVE_ASSIGN_OR_RETURN(render::SceneConfig config, BuildConfig(o));
    NAVE_ASSIGN_OR_RETURN(const double rank_timeout_s,
                          ParseDuration(o.rank_timeout, "--rank-timeout"));
    NAVE_ASSIGN_OR_RETURN(
        render::RankGroup * ranks,
        JoinRanks({.rank_timeout_s = rank_timeout_s,
                   .pack_rays = o.pack_rays == "on",
                   .coarse_levels_everywhere = o.coarse_levels_everywhere == "on"}));
    std::optional<uint64_t> memory_bytes;  // --memory, in bytes
    if (!o.memory.empty()) {
        NAVE_ASSIGN_OR_RETURN(uint64_t bytes, ParseByteSize(o.memory));
        memory_bytes = bytes;
    }

    // Huge pages for Embree's BVHs: a fresh 4 KiB page costs a fault, and on virtual machines
    // faults took as long as the BVH builds themselves (in-core abbey: 42 s -> 35 s with huge
    // pages).
    NAVE_ASSIGN_OR_RETURN(auto device, render::EmbreeDevice::Create("hugepages=1"));
    NAVE_ASSIGN_OR_RETURN(OpenedModel model, OpenModel(o, device));
    render::BrickSource& source = *model.source;
    NAVE_ASSIGN_OR_RETURN(std::unique_ptr<PreparedSession> session,
                          StartSession(o, model, config, out));
    NAVE_ASSIGN_OR_RETURN(render::RenderScene scene, render::BuildRenderScene(config, source));
    NAVE_ASSIGN_OR_RETURN(std::unique_ptr<render::TextureCache> textures,
                          AttachModelTextures(o, config, source, memory_bytes, &scene));
    log::Info("render: {} bricks{}, {} materials, {}x{}, mode {}{}", source.brick_count(),
              source.level_count() > 1
                  ? fmt::format(" at up to {} levels of detail", source.level_count())
                  : std::string(),
              scene.materials.size(), config.camera.width, config.camera.height,
              ModeName(config.render.mode),
              scene.sun >= 0 ? ", sun " + scene.sun_description : std::string());

    std::unique_ptr<TraceRecorder> trace;
    std::filesystem::path trace_path = o.trace;
    if (!o.trace.empty()) {
        trace = std::make_unique<TraceRecorder>();
        if (ranks != nullptr) {
            // A file per rank, each rank a process of its own in the viewer once merged.
            trace_path = TracePathOfRank(o.trace, ranks->rank());
            trace->NameProcess(ranks->rank(), "nave " + RankName());
        }
    }
    NAVE_ASSIGN_OR_RETURN(render::PagerOptions pager, BuildPagerOptions(o, out, trace.get()));
    // The brick sizes the memory plan counts depend on how their BVHs are built.
    NAVE_RETURN_IF_ERROR(source.SetBvhSettings(pager.bvh));
    if (memory_bytes) {
        NAVE_RETURN_IF_ERROR(PlanMemory(o, *memory_bytes, config, source, textures.get(),
                                        session->checkpoints(), &pager, &scene));
    }

    render::Film film(config.camera.width, config.camera.height, scene.output);
    render::RenderStats stats;
    NAVE_RETURN_IF_ERROR(
        render::RenderStreams(scene, &film, &stats, {}, &pager, &session->options, ranks));
    NAVE_RETURN_IF_ERROR(CheckNotInterrupted(*session, scene.settings, stats, out));
    // Free the bricks and the queues' pages before the image writer loads OpenImageIO (~120 MiB),
    // so that the two never add up (the allocator keeps freed pages a while otherwise).
    for (uint32_t b = 0; b < source.slot_count(); ++b) source.Evict(b);
    ReturnFreeMemory();

    if (trace) NAVE_RETURN_IF_ERROR(trace->Write(trace_path).WithContext("--trace"));
    // Every rank holds the whole image (RenderStreams sums the films); rank 0 writes it.
    if (ranks != nullptr && ranks->rank() != 0) return Status::Ok();
    render::RenderSummary summary(scene.settings, stats, TextureFacts(textures.get()));
    NAVE_RETURN_IF_ERROR(WriteImage(o, model, out, scene, film, summary));
    PrintSummary(o, out, &summary);
    return Status::Ok();
}

}  // namespace

void RegisterRenderCommand(CLI::App& app, CommandRun& run) {
    auto opts = std::make_shared<RenderOptions>();
    CLI::App* cmd = app.add_subcommand(
        "render",
        "Render a brick store with spectral ray streams over its bricks (path tracing or SPPM). "
        "Under mpirun the ranks share the bricks and send rays and photons to each "
        "other; rank 0 writes the image (docs/distributed.md)");
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
    cmd->add_option("--rank-timeout", opts->rank_timeout,
                    "Under mpirun: how long a rank with no ray to trace waits for rays or for the "
                    "others to finish their batches before it ends the job as hung, as 90s, 10m "
                    "or 1h (0: for ever; docs/distributed.md). Default 10m");
    cmd->add_option("--pack-rays", opts->pack_rays,
                    "Under mpirun: pack the rays sent between ranks (each message's records "
                    "transposed byte by byte, then LZ4: a few times fewer bytes for a little CPU "
                    "time), on or off (off for an interconnect faster than LZ4, ~1 GB/s a core; "
                    "docs/distributed.md). Default on")
        ->check(CLI::IsMember({"on", "off"}));
    cmd->add_option("--coarse-levels-everywhere", opts->coarse_levels_everywhere,
                    "Under mpirun, with levels of detail: every rank holds the coarse levels the "
                    "pager keeps resident (within its --memory) and traces the rays that meet "
                    "them itself instead of sending them to the brick's owner, on or off "
                    "(docs/distributed.md). Default on")
        ->check(CLI::IsMember({"on", "off"}));
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
    CLI::Option* lod =
        cmd->add_option(
               "--lod", opts->lod,
               "Levels of detail (render.lod): auto (the default) traces each ray scattered by a "
               "diffuse or glossy surface against the coarsest level of each brick its footprint "
               "allows (camera rays keep full detail), in stores made with `nave preprocess "
               "--levels`; full traces full detail everywhere (docs/render.md, \"Levels of "
               "detail\")")
            ->check(CLI::IsMember({"auto", "full"}));
    cmd->add_flag("--no-lod", opts->no_lod, "Full detail everywhere: --lod full")->excludes(lod);
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
