#include "src/render/bricks/resident_brick.h"

#include <embree3/rtcore.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "src/core/trace.h"

namespace nave::render {
namespace {

// Embree's ray over [t0, t1] from `origin` along `dir`, for a hit query and an occlusion query
// alike.
RTCRay EmbreeRay(const Vec3f& origin, const Vec3f& dir, float t0, float t1) {
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
    return ray;
}

}  // namespace

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
                                                              const BvhSettings& bvh,
                                                              LevelOfDetail lod) {
    std::unique_ptr<ResidentBrick> brick(new ResidentBrick(id, cell, std::move(mesh)));
    brick->lod_ = lod;
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
    rh.ray = EmbreeRay(origin, dir, t0, t1);
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
    RTCRay ray = EmbreeRay(origin, dir, t0, t1);
    rtcOccluded1(static_cast<RTCScene>(scene_), &context, &ray);
    return ray.tfar == -std::numeric_limits<float>::infinity();
}

}  // namespace nave::render
