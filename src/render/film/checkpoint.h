#pragma once
// Render checkpoints (`nave render --checkpoint FILE`, `--resume FILE`; docs/render.md,
// "Checkpoints"): the state of a render between two passes (path mode) or iterations (photon
// mode), from which it continues to the same image it would have made uninterrupted.
//
// File layout, little-endian:
//   header (40 bytes): magic "NAVECKPT", major u16, minor u16, section count u32, body bytes u64,
//                      XXH64 of the body u64, XXH64 of the header's first 32 bytes u64
//   body: sections, each a name (u64 length, bytes), a size u64 and that many bytes.
// Sections: "identity" (what the checkpoint belongs to), "progress" (passes or iterations done,
// seconds spent) and one per part of the render's state ("film", "path_guide", "visible_points",
// "photon_emitters"), each written and read by its owner.

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>

#include "src/core/status.h"

namespace nave::render {

inline constexpr char kCheckpointMagic[8] = {'N', 'A', 'V', 'E', 'C', 'K', 'P', 'T'};
/// 2: path mode's guide learns in overlapping rounds (PathGuide's state holds them: 2026-12-02).
inline constexpr uint16_t kCheckpointMajor = 2;
inline constexpr uint16_t kCheckpointMinor = 0;
inline constexpr uint32_t kCheckpointHeaderBytes = 40;

/// What a checkpoint belongs to: a render resumes only from a checkpoint of the same model, config
/// and nave version.
struct CheckpointIdentity {
    uint64_t model = 0;   ///< the store's header checksum (a procedural model: its name's)
    uint64_t config = 0;  ///< hash of the config file and of the options that change the image
    std::string version;  ///< the nave version that wrote it
    uint8_t mode = 0;     ///< RenderSettings::Mode
    // For messages only, never compared: the model and config as the writing run named them.
    std::string model_name;
    std::string config_name;
};

/// A render's state after `done` passes or iterations.
struct Checkpoint {
    CheckpointIdentity identity;
    uint32_t done = 0;           ///< passes (path mode) or iterations (photon mode) completed
    double elapsed_seconds = 0;  ///< rendering time so far, over every run (render.time_limit_s)
    /// The state of each part of the render, by name; their bytes are their owners' business.
    std::map<std::string, std::string> sections;

    /// The bytes of section `name`; DataLoss naming `file` if the checkpoint has none.
    StatusOr<std::string_view> Section(const std::string& name, const std::string& file) const;
};

/// Writes `checkpoint` to `path` atomically (temporary name, fsync, rename): an interruption leaves
/// the previous checkpoint in place. Errors: IoError naming the file.
Status WriteCheckpoint(const std::filesystem::path& path, const Checkpoint& checkpoint);

/// Reads a checkpoint, checking in order: size, magic, header checksum, major version, body size,
/// body checksum, sections. Errors name the file and what was expected vs found: DataLoss for a
/// truncated or corrupt file, Unsupported for another major version, NotFound for none.
StatusOr<Checkpoint> ReadCheckpoint(const std::filesystem::path& path);

/// Ok when `found` (read from checkpoint file `file`) belongs to the render `expected` describes;
/// otherwise an InvalidArgument saying which differs (model, config, mode or nave version) with
/// both values.
Status CheckCheckpointIdentity(const CheckpointIdentity& found, const CheckpointIdentity& expected,
                               const std::string& file);

}  // namespace nave::render
