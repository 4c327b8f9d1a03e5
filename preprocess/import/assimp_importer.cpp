#include "preprocess/import/assimp_importer.h"

#include <assimp/cimport.h>
#include <fmt/format.h>

#include "preprocess/import/assimp_scene.h"
#include "preprocess/import/indexed_mesh_source.h"
#include "preprocess/import/model_wire.h"
#include "src/core/child_process.h"

namespace nave::preprocess {
namespace {

// The child: reads the model with Assimp and writes it, or the error, to `fd`
// (ReportStatusFromChild: anything but those two ends, an abort or a segfault, is a crash).
int ReadInChild(const std::filesystem::path& path, int fd) {
    StatusOr<ImportedModel> model = ReadWithAssimpInProcess(path);
    if (!model.ok()) return ReportStatusFromChild(fd, model.status());
    const std::string bytes = EncodeImportedModel(*model);
    return WriteAllToFd(fd, bytes.data(), bytes.size())
               ? 0
               : ReportStatusFromChild(fd, IoError("{}: cannot send the model", path.string()));
}

// How long Assimp may take on a file: generous for what its slowest readers do with a valid file
// (a few MiB per minute of text formats and post-processing), so that only a reader stuck in a
// loop on damaged data reaches it.
constexpr double kAssimpBaseSeconds = 300;
constexpr double kAssimpSecondsPerMiB = 60;
double AssimpTimeLimitSeconds(uintmax_t file_bytes) {
    return kAssimpBaseSeconds + kAssimpSecondsPerMiB * double(file_bytes) / double(1 << 20);
}

// The last non-empty line a crashed child printed (Assimp's assertion message), shortened.
std::string LastLine(const std::string& text) {
    size_t end = text.find_last_not_of(" \r\n");
    if (end == std::string::npos) return {};
    size_t begin = text.rfind('\n', end);
    begin = begin == std::string::npos ? 0 : begin + 1;
    std::string line = text.substr(begin, end + 1 - begin);
    if (line.size() > 300) line = line.substr(0, 300) + "...";
    return line;
}

}  // namespace

bool AssimpSupports(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    return !ext.empty() && aiIsExtensionSupported(ext.c_str()) == AI_TRUE;
}

StatusOr<std::unique_ptr<TriangleSource>> OpenWithAssimp(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) return NotFoundError("{}: no such file", path.string());
    // Assimp runs in a child process: on some malformed files it aborts (ai_assert) or crashes, and
    // that must end in an error naming the file, not take nave (and a half-written store) with it.
    const uintmax_t file_bytes = std::filesystem::file_size(path, ec);
    const double time_limit = AssimpTimeLimitSeconds(ec ? 0 : file_bytes);
    NAVE_ASSIGN_OR_RETURN(
        ChildOutcome child,
        RunInChildProcess([&](int fd) { return ReadInChild(path, fd); }, time_limit));
    if (child.timed_out) {
        return DataLossError(
            "{}: the Assimp importer was stopped after {:.0f} s reading this file of {} bytes "
            "(its limit: {:.0f} s + {:.0f} s per MiB), the sign of a reader stuck on damaged data; "
            "repair or re-export it (glTF, OBJ and PLY are read by nave itself)",
            path.string(), time_limit, ec ? 0 : file_bytes, kAssimpBaseSeconds,
            kAssimpSecondsPerMiB);
    }
    if (!child.exited || child.exit_code != 0) {
        Status reported;
        if (ChildReportedStatus(child, &reported)) return reported;
        const std::string said = LastLine(child.stderr_tail);
        return DataLossError(
            "{}: the Assimp importer {} reading this file; the file is damaged or uses something "
            "{} cannot read: repair or re-export it (glTF, OBJ and PLY are read by nave itself){}",
            path.string(), DescribeChildEnd(child), AssimpVersion(),
            said.empty() ? "" : " (Assimp said: " + said + ")");
    }
    NAVE_ASSIGN_OR_RETURN(ImportedModel model, DecodeImportedModel(child.output, path.string()));
    return std::unique_ptr<TriangleSource>(
        new IndexedMeshSource(path.filename().string(), "unknown", std::move(model.meshes),
                              std::move(model.materials), ImportWarnings()));
}

}  // namespace nave::preprocess
