#include "src/render/film/checkpoint.h"

#include <cstring>

#include "src/core/byte_stream.h"
#include "src/core/file.h"
#include "src/core/hash.h"

namespace nave::render {
namespace {

// Names and small strings inside a checkpoint are short: a longer length is corruption, and must
// not make the reader allocate it.
constexpr uint64_t kMaxNameBytes = 4096;

std::string EncodeIdentity(const CheckpointIdentity& id) {
    ByteWriter w;
    w.Put(id.model);
    w.Put(id.config);
    w.PutString(id.version);
    w.Put(id.mode);
    w.PutString(id.model_name);
    w.PutString(id.config_name);
    return w.Take();
}

Status DecodeIdentity(std::string_view bytes, const std::string& file, CheckpointIdentity* id) {
    ByteReader r(bytes, file + " section identity");
    NAVE_RETURN_IF_ERROR(r.Get(&id->model, "model"));
    NAVE_RETURN_IF_ERROR(r.Get(&id->config, "config"));
    NAVE_RETURN_IF_ERROR(r.GetString(&id->version, kMaxNameBytes, "version"));
    NAVE_RETURN_IF_ERROR(r.Get(&id->mode, "mode"));
    NAVE_RETURN_IF_ERROR(r.GetString(&id->model_name, kMaxNameBytes, "model name"));
    NAVE_RETURN_IF_ERROR(r.GetString(&id->config_name, kMaxNameBytes, "config name"));
    return r.ExpectEnd();
}

const char* ModeName(uint8_t mode) { return mode == 0 ? "path" : "photon"; }

}  // namespace

StatusOr<std::string_view> Checkpoint::Section(const std::string& name,
                                               const std::string& file) const {
    auto it = sections.find(name);
    if (it == sections.end()) {
        return DataLossError(
            "{}: checkpoint has no section {} (written by another kind of render?)", file, name);
    }
    return std::string_view(it->second);
}

Status WriteCheckpoint(const std::filesystem::path& path, const Checkpoint& checkpoint) {
    NAVE_ASSIGN_OR_RETURN(AtomicFile out, AtomicFile::Create(path));
    // The body goes to the file section by section, its checksum computed on the way and the
    // header written last: the film and the guide are never copied into one buffer (under
    // --memory they can be a good part of the reserve).
    const std::string blank(kCheckpointHeaderBytes, '\0');
    NAVE_RETURN_IF_ERROR(out.Write(blank));
    StreamingChecksum64 body_sum;
    auto piece = [&](std::string_view bytes) {
        body_sum.Update(bytes.data(), bytes.size());
        return out.Write(bytes);
    };
    auto section = [&](const std::string& name, std::string_view bytes) -> Status {
        ByteWriter frame;
        frame.PutString(name);
        frame.Put(uint64_t(bytes.size()));
        NAVE_RETURN_IF_ERROR(piece(frame.bytes()));
        return piece(bytes);
    };
    NAVE_RETURN_IF_ERROR(section("identity", EncodeIdentity(checkpoint.identity)));
    ByteWriter progress;
    progress.Put(checkpoint.done);
    progress.Put(checkpoint.elapsed_seconds);
    NAVE_RETURN_IF_ERROR(section("progress", progress.bytes()));
    for (const auto& [name, bytes] : checkpoint.sections)
        NAVE_RETURN_IF_ERROR(section(name, bytes));

    ByteWriter header;
    header.Put(kCheckpointMagic);
    header.Put(kCheckpointMajor);
    header.Put(kCheckpointMinor);
    header.Put(uint32_t(2 + checkpoint.sections.size()));
    header.Put(uint64_t(out.size() - kCheckpointHeaderBytes));
    header.Put(body_sum.Digest());
    header.Put(Checksum64(header.bytes().data(), header.bytes().size()));
    NAVE_CHECK_EQ(header.bytes().size(), size_t(kCheckpointHeaderBytes));
    NAVE_RETURN_IF_ERROR(out.WriteAt(0, header.bytes().data(), header.bytes().size()));
    return out.Commit();
}

StatusOr<Checkpoint> ReadCheckpoint(const std::filesystem::path& path) {
    const std::string file = path.string();
    NAVE_ASSIGN_OR_RETURN(std::string bytes, ReadFileToString(path));
    if (bytes.size() < kCheckpointHeaderBytes) {
        return DataLossError(
            "{}: {} bytes, shorter than a checkpoint's {}-byte header: truncated, or not a nave "
            "checkpoint",
            file, bytes.size(), kCheckpointHeaderBytes);
    }
    if (std::memcmp(bytes.data(), kCheckpointMagic, sizeof(kCheckpointMagic)) != 0) {
        return DataLossError("{}: not a nave checkpoint (its first 8 bytes are not \"NAVECKPT\")",
                             file);
    }
    ByteReader header(std::string_view(bytes).substr(0, kCheckpointHeaderBytes), file + " header");
    char magic[8];
    uint16_t major = 0, minor = 0;
    uint32_t section_count = 0;
    uint64_t body_bytes = 0, body_checksum = 0, header_checksum = 0;
    NAVE_RETURN_IF_ERROR(header.Get(&magic, "magic"));
    NAVE_RETURN_IF_ERROR(header.Get(&major, "major version"));
    NAVE_RETURN_IF_ERROR(header.Get(&minor, "minor version"));
    NAVE_RETURN_IF_ERROR(header.Get(&section_count, "section count"));
    NAVE_RETURN_IF_ERROR(header.Get(&body_bytes, "body size"));
    NAVE_RETURN_IF_ERROR(header.Get(&body_checksum, "body checksum"));
    const uint64_t header_sum = Checksum64(bytes.data(), header.offset());
    NAVE_RETURN_IF_ERROR(header.Get(&header_checksum, "header checksum"));
    if (header_sum != header_checksum) {
        return DataLossError("{} header: checksum {} != stored {}: the checkpoint is corrupt", file,
                             ChecksumHex(header_sum), ChecksumHex(header_checksum));
    }
    if (major != kCheckpointMajor) {
        return UnsupportedError(
            "{}: checkpoint format {}.{}, this nave reads {}.x: resume it with the nave that wrote "
            "it, or render again",
            file, major, minor, kCheckpointMajor);
    }
    const uint64_t found_body = bytes.size() - kCheckpointHeaderBytes;
    if (found_body != body_bytes) {
        return DataLossError("{}: the header promises {} bytes after it, the file has {}{}", file,
                             body_bytes, found_body,
                             found_body < body_bytes ? " (truncated)" : " (bytes appended)");
    }
    const std::string_view body = std::string_view(bytes).substr(kCheckpointHeaderBytes);
    const uint64_t body_sum = Checksum64(body.data(), body.size());
    if (body_sum != body_checksum) {
        return DataLossError("{} body @{}: checksum {} != stored {}: the checkpoint is corrupt",
                             file, kCheckpointHeaderBytes, ChecksumHex(body_sum),
                             ChecksumHex(body_checksum));
    }

    Checkpoint checkpoint;
    ByteReader r(body, file + " body");
    std::map<std::string, std::string> sections;
    for (uint32_t s = 0; s < section_count; ++s) {
        std::string name, section;
        NAVE_RETURN_IF_ERROR(r.GetString(&name, kMaxNameBytes, "section name"));
        NAVE_RETURN_IF_ERROR(r.GetString(&section, body.size(), "section " + name));
        if (!sections.emplace(name, std::move(section)).second)
            return DataLossError("{}: section {} appears twice", file, name);
    }
    NAVE_RETURN_IF_ERROR(r.ExpectEnd());
    checkpoint.sections = std::move(sections);
    NAVE_ASSIGN_OR_RETURN(std::string_view identity, checkpoint.Section("identity", file));
    NAVE_RETURN_IF_ERROR(DecodeIdentity(identity, file, &checkpoint.identity));
    NAVE_ASSIGN_OR_RETURN(std::string_view progress_bytes, checkpoint.Section("progress", file));
    ByteReader progress(progress_bytes, file + " section progress");
    NAVE_RETURN_IF_ERROR(progress.Get(&checkpoint.done, "done"));
    NAVE_RETURN_IF_ERROR(progress.Get(&checkpoint.elapsed_seconds, "elapsed seconds"));
    NAVE_RETURN_IF_ERROR(progress.ExpectEnd());
    checkpoint.sections.erase("identity");
    checkpoint.sections.erase("progress");
    return checkpoint;
}

Status CheckCheckpointIdentity(const CheckpointIdentity& found, const CheckpointIdentity& expected,
                               const std::string& file) {
    if (found.version != expected.version) {
        return InvalidArgumentError(
            "--resume {}: written by nave {}, this is nave {}: a checkpoint resumes only with the "
            "version that wrote it",
            file, found.version, expected.version);
    }
    if (found.model != expected.model) {
        return InvalidArgumentError(
            "--resume {}: written for another model ({}, identity {}), this render's model is {} "
            "(identity {})",
            file, found.model_name, ChecksumHex(found.model), expected.model_name,
            ChecksumHex(expected.model));
    }
    if (found.mode != expected.mode) {
        return InvalidArgumentError("--resume {}: written in {} mode, this render is in {} mode",
                                    file, ModeName(found.mode), ModeName(expected.mode));
    }
    if (found.config != expected.config) {
        return InvalidArgumentError(
            "--resume {}: written for another config ({}, hash {}), this render's config is {} "
            "(hash {}): the config file and --resolution, --seed, --photons, --mode and "
            "--no-textures must be the same",
            file, found.config_name, ChecksumHex(found.config), expected.config_name,
            ChecksumHex(expected.config));
    }
    return Status::Ok();
}

}  // namespace nave::render
