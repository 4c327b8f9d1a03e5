#include "src/cli/render_checkpoint.h"

#include <fmt/format.h>

#include "src/core/duration.h"
#include "src/core/hash.h"
#include "src/core/log.h"
#include "src/core/stale_temporaries.h"
#include "src/render/film/film.h"

namespace nave::cli {
namespace {

void LogRemoved(const std::vector<std::filesystem::path>& removed) {
    for (const std::filesystem::path& p : removed)
        log::Info("render: removed {}, left by an earlier nave run that was killed", p.string());
}

std::filesystem::path DirOf(const std::filesystem::path& path) {
    return path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
}

}  // namespace

Status CheckCheckpointFlags(const CheckpointFlags& flags) {
    if (!flags.checkpoint_every.empty()) {
        NAVE_RETURN_IF_ERROR(ParseDuration(flags.checkpoint_every, "--checkpoint-every").status());
        if (flags.checkpoint.empty() && flags.resume.empty()) {
            return InvalidArgumentError(
                "--checkpoint-every {} needs --checkpoint FILE (or --resume FILE) to write to",
                flags.checkpoint_every);
        }
    }
    if (!flags.checkpoint.empty() && std::filesystem::is_directory(flags.checkpoint)) {
        return InvalidArgumentError("--checkpoint {}: is a directory, expected a file name",
                                    flags.checkpoint);
    }
    return Status::Ok();
}

render::CheckpointIdentity RenderIdentity(uint64_t model_id, const std::string& model_name,
                                          const std::string& config_path,
                                          const std::string& config_text,
                                          const render::SceneConfig& config) {
    // The config file as written, and the values options override that change the image; not
    // spp, iterations, noise or time limits, which only say when to stop, so that a resumed
    // render may go on further.
    const std::string resolved = fmt::format(
        "{}\n--resolution {}x{} --seed {} --photons {} --mode {} --textures {} --lod {}",
        config_text, config.camera.width, config.camera.height, config.render.seed,
        config.render.photons_per_iteration, int(config.render.mode), config.textures.enabled,
        int(config.render.lod));
    render::CheckpointIdentity id;
    id.model = model_id;
    id.model_name = model_name;
    id.config = Checksum64(resolved.data(), resolved.size());
    id.config_name = config_path;
    id.version = NAVE_VERSION;
    id.mode = uint8_t(config.render.mode);
    return id;
}

StatusOr<std::unique_ptr<PreparedSession>> PrepareSession(
    const CheckpointFlags& flags, const render::CheckpointIdentity& identity) {
    auto session = std::make_unique<PreparedSession>();
    render::SessionOptions& o = session->options;
    o.identity = identity;
    o.stop_after = flags.stop_after;
    if (!flags.resume.empty()) {
        NAVE_ASSIGN_OR_RETURN(session->resume, render::ReadCheckpoint(flags.resume));
        NAVE_RETURN_IF_ERROR(
            render::CheckCheckpointIdentity(session->resume->identity, identity, flags.resume));
        o.resume = &*session->resume;
        o.resume_name = flags.resume;
    }
    o.checkpoint_path = !flags.checkpoint.empty() ? flags.checkpoint : flags.resume;
    if (!flags.checkpoint_every.empty()) {
        NAVE_ASSIGN_OR_RETURN(o.checkpoint_every_s,
                              ParseDuration(flags.checkpoint_every, "--checkpoint-every"));
    }
    return session;
}

void RemoveStaleRenderTemporaries(const std::filesystem::path& output,
                                  const std::filesystem::path& checkpoint) {
    // Images and checkpoints are written through "<name>.tmp-<pid>-<n>" (AtomicFile).
    const std::filesystem::path png = render::Film::DisplayPathOf(output);
    LogRemoved(RemoveStaleTemporaries(DirOf(output), output.filename().string() + ".tmp-"));
    LogRemoved(RemoveStaleTemporaries(DirOf(png), png.filename().string() + ".tmp-"));
    if (!checkpoint.empty())
        LogRemoved(
            RemoveStaleTemporaries(DirOf(checkpoint), checkpoint.filename().string() + ".tmp-"));
}

}  // namespace nave::cli
