#include "src/render/bricks/brick_cache.h"

#include "src/core/log.h"
#include "src/core/memory.h"

namespace nave::render {
namespace {

template <typename T>
StatusOr<store::SpillExtent> WriteVector(store::SpillFile& file, const std::vector<T>& v) {
    return file.Write(v.data(), v.size() * sizeof(T));
}

/// Reads `extent` into `out`, which must hold exactly its bytes.
template <typename T>
Status ReadSpan(const store::SpillFile& file, const store::SpillExtent& extent, std::span<T> out) {
    if (extent.raw_bytes != out.size_bytes()) {
        return InternalError("a cached array holds {} bytes where {} were expected",
                             extent.raw_bytes, out.size_bytes());
    }
    return out.empty() ? Status::Ok() : file.Read(extent, out.data());
}

}  // namespace

BrickCache::BrickCache(std::unique_ptr<store::SpillFile> file, uint32_t brick_count,
                       uint64_t limit_bytes)
    : file_(std::move(file)), limit_bytes_(limit_bytes) {
    entries_.reserve(brick_count);
    for (uint32_t b = 0; b < brick_count; ++b) entries_.push_back(std::make_unique<Entry>());
}

BrickCache::~BrickCache() = default;

bool BrickCache::Has(uint32_t id) const {
    return id < entries_.size() && entries_[id]->ready.load(std::memory_order_acquire);
}

void BrickCache::Put(uint32_t id, const store::BrickMesh& mesh) {
    if (id >= entries_.size() || Has(id)) return;
    const uint64_t mesh_bytes = mesh.MemoryBytes();
    {
        std::lock_guard<std::mutex> lock(mutex_);
        // The decoded size bounds what it takes on disk (LZ4 never stores more than that here).
        if (failed_ || stats_.disk_bytes + mesh_bytes > limit_bytes_) {
            ++stats_.skipped;
            return;
        }
        stats_.disk_bytes += mesh_bytes;  // held until the real size is known
    }
    Entry& e = *entries_[id];
    std::vector<store::SpillExtent*> written;
    Status status = Status::Ok();
    auto write = [&](store::SpillExtent* extent, StatusOr<store::SpillExtent> result) {
        if (!status.ok()) return;
        if (!result.ok()) {
            status = result.status();
            return;
        }
        *extent = std::move(result).value();
        written.push_back(extent);
    };
    write(&e.positions, WriteVector(*file_, mesh.positions));
    write(&e.normal_data, WriteVector(*file_, mesh.normals));
    write(&e.uv_data, WriteVector(*file_, mesh.uvs));
    write(&e.indices, WriteVector(*file_, mesh.indices));
    write(&e.materials, WriteVector(*file_, mesh.material_ids));
    uint64_t stored = 0;
    for (store::SpillExtent* x : written) stored += x->stored_bytes;
    std::lock_guard<std::mutex> lock(mutex_);
    stats_.disk_bytes -= mesh_bytes;
    if (!status.ok()) {
        for (store::SpillExtent* x : written) file_->Release(*x);
        ++stats_.skipped;
        if (!failed_) {
            failed_ = true;
            log::Warning("brick cache: {}; later loads decode from the store", status.message());
        }
        return;
    }
    e.counts = {mesh.VertexCount(), mesh.TriangleCount(), mesh.HasNormals(), mesh.HasUvs()};
    stats_.disk_bytes += stored;
    stats_.mesh_bytes += mesh_bytes;
    ++stats_.bricks_written;
    e.ready.store(true, std::memory_order_release);
}

StatusOr<ResidentMesh> BrickCache::Get(uint32_t id) const {
    if (!Has(id)) return InternalError("brick {} is not in the brick cache", id);
    const Entry& e = *entries_[id];
    ResidentMesh::Writable w;
    NAVE_ASSIGN_OR_RETURN(ResidentMesh mesh, ResidentMesh::Allocate(e.counts, &w));
    Status s = ReadSpan(*file_, e.positions, w.positions);
    if (s.ok()) s = ReadSpan(*file_, e.normal_data, w.normals);
    if (s.ok()) s = ReadSpan(*file_, e.uv_data, w.uvs);
    if (s.ok()) s = ReadSpan(*file_, e.indices, w.indices);
    if (s.ok()) s = ReadSpan(*file_, e.materials, w.material_ids);
    if (!s.ok()) return s.WithContext(fmt::format("reading brick {} from the brick cache", id));
    std::lock_guard<std::mutex> lock(mutex_);
    ++stats_.reads;
    return mesh;
}

BrickCacheStats BrickCache::stats() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return stats_;
}

}  // namespace nave::render
