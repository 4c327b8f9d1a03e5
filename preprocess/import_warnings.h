#pragma once
// Counted warnings for problems an importer can skip over: one line per kind at the end of a run,
// with the count and the first place it happened ("skipped 12 degenerate faces (first at
// bunny.ply:1234)"), instead of thousands of lines.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace nave::preprocess {

class ImportWarnings {
  public:
    /// Counts one occurrence of `what` ("degenerate faces skipped") at `where` ("bunny.ply:1234").
    void Add(const std::string& what, const std::string& where);
    /// Adds all of `other`'s counts (merging several inputs).
    void Merge(const ImportWarnings& other);

    uint64_t Count(const std::string& what) const;
    uint64_t Total() const;
    bool Empty() const { return kinds_.empty(); }
    /// One line per kind: "degenerate faces skipped: 12 (first at bunny.ply:1234)".
    std::vector<std::string> Summary() const;

  private:
    struct Kind {
        uint64_t count = 0;
        std::string first;
    };
    std::map<std::string, Kind> kinds_;
};

}  // namespace nave::preprocess
