#pragma once
// The temporary directory of one preprocess run, and interruption. The directory is removed when
// the run ends, succeeds or fails. The caller's signal handler stores the signal in a flag that the
// work loops poll (CheckCancelled), so the run unwinds normally and removes its files. Leftovers
// of a run that was killed outright (SIGKILL, power loss) are removed by the next run in the same
// place: their names carry the dead process's id.

#include <atomic>
#include <filesystem>
#include <string>

#include "src/core/status.h"

namespace nave::preprocess {

class TempDir {
  public:
    /// Creates `<parent>/.nave-tmp-<pid>-<n>`, after removing stale ones of dead processes.
    static StatusOr<TempDir> Create(const std::filesystem::path& parent);
    TempDir(TempDir&& other) noexcept : path_(std::move(other.path_)) { other.path_.clear(); }
    TempDir& operator=(TempDir&&) = delete;
    TempDir(const TempDir&) = delete;
    ~TempDir();

    const std::filesystem::path& path() const { return path_; }
    /// "<dir>/<name>"
    std::filesystem::path File(const std::string& name) const { return path_ / name; }
    /// A failed write of a temporary file (a full disk, most often) with where the temporary files
    /// go and how to move them: "writing temporary files in <parent> (--temp-dir chooses where):
    /// ...". Ok stays Ok.
    Status Annotate(Status s) const;

  private:
    explicit TempDir(std::filesystem::path path) : path_(std::move(path)) {}
    std::filesystem::path path_;
};

/// Removes `<output>.tmp-<pid>-*` files (AtomicFile temporaries) left by dead processes next to
/// `output`.
void RemoveStaleOutputTemporaries(const std::filesystem::path& output);

/// A Cancelled status ("interrupted by signal N") once `interrupt` holds a signal number, or Ok
/// (also when `interrupt` is null).
Status CheckCancelled(const std::atomic<int>* interrupt);

}  // namespace nave::preprocess
