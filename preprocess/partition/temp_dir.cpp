#include "preprocess/partition/temp_dir.h"

#include <unistd.h>

#include <vector>

#include "src/core/log.h"
#include "src/core/stale_temporaries.h"

namespace nave::preprocess {
namespace {

/// Says which leftovers of killed runs were removed: a user who finds space freed, or a file gone,
/// learns why.
void LogRemoved(const std::vector<std::filesystem::path>& removed) {
    for (const std::filesystem::path& p : removed)
        log::Info("removed {}, left by an earlier nave run that was killed", p.string());
}

}  // namespace

StatusOr<TempDir> TempDir::Create(const std::filesystem::path& parent) {
    std::error_code ec;
    std::filesystem::path dir = parent.empty() ? std::filesystem::path(".") : parent;
    if (!std::filesystem::is_directory(dir, ec)) {
        return NotFoundError("{}: temporary directory parent does not exist", dir.string());
    }
    const std::string prefix = ".nave-tmp-";
    LogRemoved(RemoveStaleTemporaries(dir, prefix));
    static std::atomic<int> counter{0};
    for (int attempt = 0; attempt < 100; ++attempt) {
        auto path = dir / (prefix + std::to_string(::getpid()) + "-" + std::to_string(counter++));
        if (std::filesystem::create_directory(path, ec)) return TempDir(path);
        if (ec)
            return IoError("{}: cannot create temporary directory: {}", path.string(),
                           ec.message());
    }
    return IoError("{}: cannot create a temporary directory", dir.string());
}

Status TempDir::Annotate(Status s) const {
    if (s.ok()) return s;
    return s.WithContext("writing temporary files in " + path_.parent_path().string() +
                         " (--temp-dir chooses where)");
}

TempDir::~TempDir() {
    if (path_.empty()) return;
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
}

void RemoveStaleOutputTemporaries(const std::filesystem::path& output) {
    const std::filesystem::path dir =
        output.has_parent_path() ? output.parent_path() : std::filesystem::path(".");
    LogRemoved(RemoveStaleTemporaries(dir, output.filename().string() + ".tmp-"));
}

Status CheckCancelled(const std::atomic<int>* interrupt) {
    const int sig = interrupt ? interrupt->load(std::memory_order_relaxed) : 0;
    if (sig == 0) return Status::Ok();
    return Status(StatusCode::kCancelled, "interrupted by signal " + std::to_string(sig) +
                                              ": output and temporary files removed");
}

}  // namespace nave::preprocess
