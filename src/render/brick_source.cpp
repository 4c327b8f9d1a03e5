#include "render/brick_source.h"

#include <embree3/rtcore.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "core/trace.h"
#include "render/brick_mesh_cache.h"

namespace nave::render {
uint64_t BvhSettings::BytesPerTriangle() const {
    // Embree's own count of its allocations (its memory monitor) after building abbey bricks of
    // 0.1-1 M triangles, rounded up: bench_brick_load's bvh_bytes/triangle (docs/pager.md).
    // Measured on brick 63 (700 k triangles): low 85.8, low compact 46.9, medium and high 65.9,
    // medium and high compact 34.2.
    switch (quality) {
        case Quality::kLow:
            return compact ? 50 : 90;
        case Quality::kMedium:
        case Quality::kHigh:
            return compact ? 38 : 70;
    }
    return 90;
}

// ----------------------------------------------------------------------------------------------
// Embree

StatusOr<std::shared_ptr<EmbreeDevice>> EmbreeDevice::Create(const std::string& config) {
    std::shared_ptr<EmbreeDevice> device(new EmbreeDevice());
    RTCDevice handle = rtcNewDevice(config.empty() ? nullptr : config.c_str());
    if (handle == nullptr) {
        return InternalError("Embree: cannot create a device with config '{}' (error {})", config,
                             int(rtcGetDeviceError(nullptr)));
    }
    device->device_ = handle;
    rtcSetDeviceErrorFunction(
        handle,
        [](void* user, RTCError code, const char* message) {
            EmbreeDevice::ErrorCallback(user, int(code), message);
        },
        device.get());
    return device;
}

EmbreeDevice::~EmbreeDevice() {
    if (device_ != nullptr) rtcReleaseDevice(static_cast<RTCDevice>(device_));
}

void EmbreeDevice::ErrorCallback(void* user, int code, const char* message) {
    auto* self = static_cast<EmbreeDevice*>(user);
    std::lock_guard<std::mutex> lock(self->mutex_);
    if (self->error_.ok()) {
        self->error_ =
            Status(code == RTC_ERROR_OUT_OF_MEMORY ? StatusCode::kResourceExhausted
                                                   : StatusCode::kInternal,
                   fmt::format("Embree error {}: {}", code, message ? message : "(no message)"));
    }
}

Status EmbreeDevice::TakeError(const std::string& context) {
    std::lock_guard<std::mutex> lock(mutex_);
    Status s = error_;
    error_ = Status::Ok();
    return s.ok() ? s : s.WithContext(context);
}

// ----------------------------------------------------------------------------------------------
// ResidentBrick

ResidentBrick::ResidentBrick(uint32_t id, Bounds3f cell, ResidentMesh mesh)
    : id_(id), cell_(cell), mesh_(std::move(mesh)) {}

ResidentBrick::~ResidentBrick() {
    if (scene_ != nullptr) rtcReleaseScene(static_cast<RTCScene>(scene_));
}

namespace {

/// Embree's intersection and occlusion filter for bricks with cut-outs: a hit where the material's
/// alpha mask says the surface is absent is rejected, and the ray goes on to the next surface
/// (Embree 3 RTCFilterFunctionN: clear valid[i] to reject hit i).
void AlphaFilter(const RTCFilterFunctionNArguments* args) {
    const auto* brick = static_cast<const ResidentBrick*>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        const uint32_t prim = RTCHitN_primID(args->hit, args->N, i);
        if (!brick->SurfacePresent(prim, RTCHitN_u(args->hit, args->N, i),
                                   RTCHitN_v(args->hit, args->N, i)))
            args->valid[i] = 0;
    }
}

/// Whether any triangle of `m` has a material with an alpha mask.
bool NeedsAlphaFilter(const ResidentMesh& m, const AlphaMasks* masks) {
    if (masks == nullptr || masks->empty() || !m.HasUvs()) return false;
    std::vector<bool> seen(masks->size(), false);
    for (uint32_t id : m.material_ids) {
        if (id < masks->size() && !seen[id]) {
            if ((*masks)[id] != nullptr) return true;
            seen[id] = true;
        }
    }
    return false;
}

}  // namespace

bool ResidentBrick::SurfacePresent(uint32_t triangle, float u, float v) const {
    const uint32_t material = mesh_.material_ids[triangle];
    if (masks_ == nullptr || material >= masks_->size() || (*masks_)[material] == nullptr)
        return true;
    const uint32_t* tri = &mesh_.indices[3 * size_t(triangle)];
    const float w = 1.f - u - v;
    std::array<float, 2> uv;
    for (int k = 0; k < 2; ++k)
        uv[k] = mesh_.uvs[tri[0]][k] * w + mesh_.uvs[tri[1]][k] * u + mesh_.uvs[tri[2]][k] * v;
    return (*masks_)[material]->Present(uv);
}

StatusOr<std::unique_ptr<ResidentBrick>> ResidentBrick::Build(EmbreeDevice& device, uint32_t id,
                                                              Bounds3f cell, ResidentMesh mesh,
                                                              const AlphaMasks* masks,
                                                              const BvhSettings& bvh) {
    std::unique_ptr<ResidentBrick> brick(new ResidentBrick(id, cell, std::move(mesh)));
    const ResidentMesh& m = brick->mesh_;
    RTCDevice dev = static_cast<RTCDevice>(device.handle());
    RTCScene scene = rtcNewScene(dev);
    brick->scene_ = scene;
    const std::string context = fmt::format("building the Embree scene of brick {}", id);
    if (scene == nullptr) return device.TakeError(context);
    rtcSetSceneFlags(
        scene, RTCSceneFlags(RTC_SCENE_FLAG_ROBUST | (bvh.compact ? RTC_SCENE_FLAG_COMPACT : 0)));
    const RTCBuildQuality quality =
        bvh.quality == BvhSettings::Quality::kLow      ? RTC_BUILD_QUALITY_LOW
        : bvh.quality == BvhSettings::Quality::kMedium ? RTC_BUILD_QUALITY_MEDIUM
                                                       : RTC_BUILD_QUALITY_HIGH;
    rtcSetSceneBuildQuality(scene, quality);
    if (m.TriangleCount() > 0) {
        RTCGeometry geom = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetGeometryBuildQuality(geom, quality);
        rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                   m.positions.data(), 0, sizeof(Vec3f), m.positions.size());
        rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                   m.indices.data(), 0, 3 * sizeof(uint32_t), m.TriangleCount());
        if (NeedsAlphaFilter(m, masks)) {
            brick->masks_ = masks;
            rtcSetGeometryUserData(geom, brick.get());
            rtcSetGeometryIntersectFilterFunction(geom, AlphaFilter);
            rtcSetGeometryOccludedFilterFunction(geom, AlphaFilter);
        }
        rtcCommitGeometry(geom);
        rtcAttachGeometry(scene, geom);
        rtcReleaseGeometry(geom);
    }
    rtcCommitScene(scene);
    NAVE_RETURN_IF_ERROR(device.TakeError(context));
    brick->memory_bytes_ = m.MemoryBytes() + bvh.BytesPerTriangle() * uint64_t(m.TriangleCount());
    return brick;
}

StatusOr<std::unique_ptr<ResidentBrick>> ResidentBrick::Build(EmbreeDevice& device, uint32_t id,
                                                              Bounds3f cell,
                                                              const store::BrickMesh& mesh,
                                                              const AlphaMasks* masks,
                                                              const BvhSettings& bvh) {
    NAVE_ASSIGN_OR_RETURN(ResidentMesh copy, ResidentMesh::CopyOf(mesh));
    return Build(device, id, cell, std::move(copy), masks, bvh);
}

uint64_t ResidentBrick::EstimateMemoryBytes(uint64_t vertex_count, uint64_t triangle_count,
                                            bool has_normals, bool has_uvs,
                                            const BvhSettings& bvh) {
    return ResidentMesh::MemoryBytesFor({vertex_count, triangle_count, has_normals, has_uvs}) +
           bvh.BytesPerTriangle() * triangle_count;
}

bool ResidentBrick::Intersect(const Vec3f& origin, const Vec3f& dir, float t0, float t1,
                              BrickHit* hit) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray.org_x = origin.x;
    rh.ray.org_y = origin.y;
    rh.ray.org_z = origin.z;
    rh.ray.dir_x = dir.x;
    rh.ray.dir_y = dir.y;
    rh.ray.dir_z = dir.z;
    rh.ray.tnear = t0;
    rh.ray.tfar = t1;
    rh.ray.time = 0;
    rh.ray.mask = 0xffffffffu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(static_cast<RTCScene>(scene_), &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit->t = rh.ray.tfar;
    hit->u = rh.hit.u;
    hit->v = rh.hit.v;
    hit->triangle = rh.hit.primID;
    hit->ng = {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
    return true;
}

bool ResidentBrick::Occluded(const Vec3f& origin, const Vec3f& dir, float t0, float t1) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray;
    ray.org_x = origin.x;
    ray.org_y = origin.y;
    ray.org_z = origin.z;
    ray.dir_x = dir.x;
    ray.dir_y = dir.y;
    ray.dir_z = dir.z;
    ray.tnear = t0;
    ray.tfar = t1;
    ray.time = 0;
    ray.mask = 0xffffffffu;
    ray.id = 0;
    ray.flags = 0;
    rtcOccluded1(static_cast<RTCScene>(scene_), &context, &ray);
    return ray.tfar == -std::numeric_limits<float>::infinity();
}

// ----------------------------------------------------------------------------------------------
// handles

BrickHandle& BrickHandle::operator=(BrickHandle&& o) noexcept {
    if (this != &o) {
        Reset();
        source_ = o.source_;
        brick_ = o.brick_;
        o.source_ = nullptr;
        o.brick_ = nullptr;
    }
    return *this;
}

void BrickHandle::Reset() {
    if (source_ != nullptr && brick_ != nullptr) source_->Release(brick_->id());
    source_ = nullptr;
    brick_ = nullptr;
}

// ----------------------------------------------------------------------------------------------
// BrickSource

BrickSource::BrickSource(std::shared_ptr<EmbreeDevice> device, store::BrickTree tree,
                         std::vector<Bounds3f> cells, std::vector<store::MaterialRecord> materials,
                         Bounds3f bounds)
    : device_(std::move(device)),
      tree_(std::move(tree)),
      cells_(std::move(cells)),
      materials_(std::move(materials)),
      bounds_(bounds) {
    slots_.reserve(cells_.size());
    for (size_t i = 0; i < cells_.size(); ++i) slots_.push_back(std::make_unique<Slot>());
}

BrickSource::~BrickSource() = default;

StatusOr<BrickHandle> BrickSource::Acquire(uint32_t id) {
    if (id >= slots_.size()) {
        return InvalidArgumentError("brick {} requested but the model has {} bricks", id,
                                    slots_.size());
    }
    acquires_.fetch_add(1, std::memory_order_relaxed);
    Slot& slot = *slots_[id];
    // Pin first, then check: an evictor takes the slot lock and refuses while pins > 0.
    slot.pins.fetch_add(1, std::memory_order_acq_rel);
    if (const ResidentBrick* b = slot.ready.load(std::memory_order_acquire))
        return BrickHandle(this, b);
    std::lock_guard<std::mutex> lock(slot.mutex);
    if (const ResidentBrick* b = slot.ready.load(std::memory_order_acquire))
        return BrickHandle(this, b);
    if (!slot.error.ok()) {
        slot.pins.fetch_sub(1, std::memory_order_acq_rel);
        return slot.error;
    }
    auto start = std::chrono::steady_clock::now();
    TraceSpan load(trace_, "load", "pager");
    load.AddArg({"brick", id});
    uint64_t bytes = 0;
    const bool cached = mesh_cache_ != nullptr && mesh_cache_->Has(id);
    TraceSpan decode(trace_, cached ? "read from the brick cache" : "read and decode", "pager");
    // The mesh ends in pages of its own (ResidentMesh): read back from the cache straight into
    // them, or decoded into the heap and copied, so that what the heap holds is freed before the
    // next load.
    StatusOr<ResidentMesh> mesh = ResidentMesh();
    if (cached) {
        mesh = mesh_cache_->Get(id);
    } else {
        if (decode_limit_ > 0) {
            std::unique_lock<std::mutex> decode_lock(decode_mutex_);
            decode_cv_.wait(decode_lock, [&] { return decodes_ < decode_limit_; });
            ++decodes_;
        }
        StatusOr<store::BrickMesh> decoded = LoadMesh(id, &bytes);
        if (decoded.ok() && mesh_cache_ != nullptr) {
            TraceSpan put(trace_, "write to the brick cache", "pager");
            mesh_cache_->Put(id, *decoded);
        }
        mesh = decoded.ok() ? ResidentMesh::CopyOf(*decoded)
                            : StatusOr<ResidentMesh>(decoded.status());
        if (decode_limit_ > 0) {
            {
                std::lock_guard<std::mutex> decode_lock(decode_mutex_);
                --decodes_;
            }
            decode_cv_.notify_one();
        }
    }
    decode.End();
    if (mesh.ok()) load.AddArg({"triangles", mesh->TriangleCount()});
    load.AddArg({"bytes_read", bytes});
    TraceSpan build(trace_, "bvh build", "pager");
    StatusOr<std::unique_ptr<ResidentBrick>> built =
        mesh.ok() ? ResidentBrick::Build(*device_, id, cells_[id], std::move(mesh).value(),
                                         &alpha_masks_, bvh_)
                  : StatusOr<std::unique_ptr<ResidentBrick>>(mesh.status());
    build.End();
    double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!built.ok()) {
        slot.error = built.status().WithContext(fmt::format("loading brick {}", id));
        slot.pins.fetch_sub(1, std::memory_order_acq_rel);
        return slot.error;
    }
    slot.brick = std::move(built).value();
    {
        std::lock_guard<std::mutex> stats_lock(stats_mutex_);
        stats_.loads += 1;
        stats_.bytes_read += bytes;
        stats_.load_seconds += seconds;
        stats_.resident_bytes += slot.brick->memory_bytes();
        stats_.peak_resident_bytes = std::max(stats_.peak_resident_bytes, stats_.resident_bytes);
    }
    slot.ready.store(slot.brick.get(), std::memory_order_release);
    return BrickHandle(this, slot.brick.get());
}

void BrickSource::SetAlphaMasks(AlphaMasks masks) {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    NAVE_CHECK_EQ(stats_.resident_bytes, 0u) << "alpha masks set while bricks are resident";
    alpha_masks_ = std::move(masks);
}

Status BrickSource::SetBvhSettings(const BvhSettings& bvh) {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    if (bvh == bvh_) return Status::Ok();
    if (stats_.resident_bytes != 0) {
        return InvalidArgumentError(
            "the BVH settings of a brick source cannot change while {} of bricks are resident",
            stats_.resident_bytes);
    }
    bvh_ = bvh;
    return Status::Ok();
}

void BrickSource::Release(uint32_t id) {
    uint32_t before = slots_[id]->pins.fetch_sub(1, std::memory_order_acq_rel);
    NAVE_CHECK_GT(before, 0u) << "brick " << id << " released more often than acquired";
}

bool BrickSource::IsResident(uint32_t id) const {
    return id < slots_.size() && slots_[id]->ready.load(std::memory_order_acquire) != nullptr;
}

bool BrickSource::Evict(uint32_t id) {
    if (id >= slots_.size()) return false;
    Slot& slot = *slots_[id];
    std::lock_guard<std::mutex> lock(slot.mutex);
    if (slot.brick == nullptr || slot.pins.load(std::memory_order_acquire) != 0) return false;
    slot.ready.store(nullptr, std::memory_order_release);
    // A reader that pinned between our check and the store above would hold a dangling pointer;
    // re-check.
    if (slot.pins.load(std::memory_order_acquire) != 0) {
        slot.ready.store(slot.brick.get(), std::memory_order_release);
        return false;
    }
    uint64_t bytes = slot.brick->memory_bytes();
    slot.brick.reset();
    std::lock_guard<std::mutex> stats_lock(stats_mutex_);
    stats_.evictions += 1;
    stats_.resident_bytes -= bytes;
    return true;
}

BrickSourceStats BrickSource::stats() const {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    BrickSourceStats s = stats_;
    s.acquires = acquires_.load(std::memory_order_relaxed);
    return s;
}

// ----------------------------------------------------------------------------------------------
// memory source

namespace {
Bounds3f MeshesBounds(const std::vector<store::BrickMesh>& meshes) {
    Bounds3f b;
    for (const auto& m : meshes) {
        for (const Vec3f& p : m.positions) b.Extend(p);
    }
    return b;
}
}  // namespace

MemoryBrickSource::MemoryBrickSource(std::shared_ptr<EmbreeDevice> device, store::BrickTree tree,
                                     std::vector<store::BrickMesh> meshes,
                                     std::vector<store::MaterialRecord> materials)
    : BrickSource(std::move(device), tree, tree.BrickCells(uint32_t(meshes.size())),
                  std::move(materials), MeshesBounds(meshes)),
      meshes_(std::move(meshes)) {}

uint64_t MemoryBrickSource::EstimatedResidentBytes(uint32_t id) const {
    const store::BrickMesh& m = meshes_[id];
    return ResidentBrick::EstimateMemoryBytes(m.VertexCount(), m.TriangleCount(), m.HasNormals(),
                                              m.HasUvs(), bvh_settings());
}

StatusOr<store::BrickMesh> MemoryBrickSource::LoadMesh(uint32_t id, uint64_t* bytes_read) {
    *bytes_read += meshes_[id].MemoryBytes();
    return meshes_[id];
}

}  // namespace nave::render
