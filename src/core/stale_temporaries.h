#pragma once
// Temporary files and directories of nave runs that were killed outright (SIGKILL, power loss)
// before they could remove them. Every temporary name nave makes carries its process id,
// "<prefix><pid>-<n><suffix>" (AtomicFile, image writes, preprocess's work directory), so a later
// run writing into the same place can tell its dead predecessors' leftovers from the files of a
// run still going, and remove them.

#include <filesystem>
#include <string_view>
#include <vector>

namespace nave {

/// The process id in `name` if it reads "<prefix><pid>-<n><suffix>" (pid and n decimal), else -1.
long TemporaryOwner(std::string_view name, std::string_view prefix, std::string_view suffix);

/// Whether process `pid` exists (on this machine).
bool ProcessAlive(long pid);

/// Removes the entries of `dir` named "<prefix><pid>-<n><suffix>" whose process is gone (never this
/// process's), directories with what they hold, and returns their paths. Errors (an unreadable
/// directory, a file that will not go) leave things as they are: the leftovers only cost space.
std::vector<std::filesystem::path> RemoveStaleTemporaries(const std::filesystem::path& dir,
                                                          std::string_view prefix,
                                                          std::string_view suffix = {});

}  // namespace nave
