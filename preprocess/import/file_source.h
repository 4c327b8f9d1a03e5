#pragma once
// What the importers that stream one model file share (OBJ, PLY, STL): the file's reader, the
// material table, the warnings, and the TriangleSource accessors over them, written once here.

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "preprocess/import/stream_reader.h"
#include "preprocess/triangle_source.h"

namespace nave::preprocess {

/// A TriangleSource that reads one file forward: named after the file, its progress the bytes read
/// of the file's size. Subclasses parse: they fill `materials_` and `warnings_` as they read.
class FileSource : public TriangleSource {
  public:
    const std::vector<store::MaterialRecord>& materials() const final { return materials_; }
    std::string name() const final { return reader_.path().filename().string(); }
    uint64_t progress_done() const final { return reader_.offset(); }
    uint64_t progress_total() const final { return reader_.file_size(); }
    const ImportWarnings& warnings() const final { return warnings_; }

  protected:
    explicit FileSource(StreamReader reader) : reader_(std::move(reader)) {}

    StreamReader reader_;
    std::vector<store::MaterialRecord> materials_;
    ImportWarnings warnings_;
};

/// A FileSource whose faces index vertices defined before them (OBJ, PLY): it keeps every vertex
/// read so far, and memory_bytes() counts those arrays.
class FileSourceWithVertices : public FileSource {
  public:
    uint64_t memory_bytes() const final {
        return positions_.capacity() * sizeof(Vec3f) + normals_.capacity() * sizeof(Vec3f) +
               uvs_.capacity() * sizeof(uvs_[0]);
    }

  protected:
    using FileSource::FileSource;

    std::vector<Vec3f> positions_, normals_;
    std::vector<std::array<float, 2>> uvs_;
};

}  // namespace nave::preprocess
