#pragma once
// `nave render`'s checkpoint options (--checkpoint, --checkpoint-every, --resume, --stop-after):
// checked, turned into the render's SessionOptions, and the identity a checkpoint must match.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "src/core/status.h"
#include "src/render/integrators/render_session.h"
#include "src/render/scene/scene_config.h"

namespace nave::cli {

struct CheckpointFlags {
    std::string checkpoint;        ///< --checkpoint FILE
    std::string checkpoint_every;  ///< --checkpoint-every DURATION
    std::string resume;            ///< --resume FILE
    int stop_after = 0;            ///< --stop-after N
};

/// The run's session and what it points at.
struct PreparedSession {
    std::optional<render::Checkpoint> resume;
    render::SessionOptions options;
    /// Whether this run writes checkpoints.
    bool checkpoints() const { return !options.checkpoint_path.empty(); }
};

/// Checks the flags before anything is loaded: --checkpoint-every's duration and that it comes
/// with a checkpoint file. Errors: InvalidArgument naming the option.
Status CheckCheckpointFlags(const CheckpointFlags& flags);

/// What a checkpoint of this render must match: the model's identity `model_id` (named
/// `model_name` in messages), the config file's bytes `config_text` (from `config_path`) with the
/// values of `config` that options may have changed and that change the image, and this nave's
/// version.
render::CheckpointIdentity RenderIdentity(uint64_t model_id, const std::string& model_name,
                                          const std::string& config_path,
                                          const std::string& config_text,
                                          const render::SceneConfig& config);

/// Reads and checks --resume against `identity` and fills the session's options. With --resume
/// and no --checkpoint, checkpoints go on to the file resumed from. Errors: those of
/// ReadCheckpoint and CheckCheckpointIdentity.
StatusOr<std::unique_ptr<PreparedSession>> PrepareSession(
    const CheckpointFlags& flags, const render::CheckpointIdentity& identity);

/// Removes, and logs, temporaries of killed renders beside `output` (its EXR and PNG) and beside
/// `checkpoint` (may be empty).
void RemoveStaleRenderTemporaries(const std::filesystem::path& output,
                                  const std::filesystem::path& checkpoint);

}  // namespace nave::cli
