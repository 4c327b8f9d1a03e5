#pragma once
// A test's own directory under the system's temp folder, removed with everything in it when the
// test leaves its scope: also when an assertion fails and returns early.

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>

namespace nave::test {

class ScratchDir {
  public:
    /// A new empty directory "nave_<tag>_XXXXXX" (mkdtemp: unique across processes and runs).
    explicit ScratchDir(std::string_view tag) {
        std::string pattern =
            (std::filesystem::temp_directory_path() / ("nave_" + std::string(tag) + "_XXXXXX"))
                .string();
        if (::mkdtemp(pattern.data()) == nullptr) {
            ADD_FAILURE() << "cannot create a scratch directory from " << pattern;
        }
        path_ = pattern;
    }
    ~ScratchDir() {
        std::error_code ignored;
        std::filesystem::remove_all(path_, ignored);
    }
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;
    ScratchDir(ScratchDir&& o) noexcept : path_(std::move(o.path_)) { o.path_.clear(); }

    const std::filesystem::path& path() const& { return path_; }
    operator const std::filesystem::path&() const& { return path_; }  // NOLINT: used as a path
    // A temporary's path would name a directory already removed.
    const std::filesystem::path& path() const&& = delete;
    operator const std::filesystem::path&() const&& = delete;
    std::filesystem::path operator/(const std::filesystem::path& p) const { return path_ / p; }
    std::string string() const { return path_.string(); }

  private:
    std::filesystem::path path_;
};

}  // namespace nave::test
