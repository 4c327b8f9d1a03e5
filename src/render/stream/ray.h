#pragma once
// The compact record of a ray in flight. Everything a worker needs to continue the ray in whichever
// brick it lands in travels with it: geometry, the segment in the current brick, the path's
// identity (for the counter-based random numbers), its throughput and wavelengths.

#include <bit>
#include <cstdint>

#include "src/core/spectrum.h"
#include "src/core/vecmath.h"
#include "src/render/scene/media/medium_index.h"

namespace nave::render {

enum RayKind : uint8_t {
    kPathRay = 0,    ///< camera ray or continuation of a camera path
    kShadowRay = 1,  ///< carries a potential contribution, added if nothing occludes it up to t_max
    kPhotonRay = 2,  ///< a photon of SPPM's photon pass
};

enum RayFlags : uint8_t {
    kSpecularBounce =
        1 << 0,  ///< the last scattering was specular (no light sampling possible there)
    kFromAreaLight =
        1 << 1,  ///< photon emitted by a surface (its direct light is not next-event estimated)
    kFromSky = 1 << 2,    ///< photon from the sky
    kGathering = 1 << 3,  ///< photon mode's camera path past its first diffuse vertex, looking for
                          ///< the vertex whose photons it reads (render.final_gather)
    /// Photons: every bounce so far was specular, and there was one (a caustic photon, Jensen
    /// 1996). Gathering camera paths: every bounce past the first diffuse vertex was, and there was
    /// one.
    kSpecularChain = 1 << 4,
    kChainBroken = 1 << 5,  ///< a non-specular bounce happened where kSpecularChain looks
    /// Shadow rays toward the sky (LightSampler::SampleSky) where its windows learn
    /// (LightSampler::sky_windows): the ones that reach it teach them (LearnFromSkyShadow).
    kSkyShadow = 1 << 6,
    /// Photons in a medium: the stretch from the photon's origin (far outside the model) to the
    /// first brick it enters is still to be flown, by that brick (SppmIntegrator::ProcessBatch).
    kFlightFromOrigin = 1 << 7,
};

/// RayRecord::guide_side of a path whose last vertex was a scattering in a medium, which has no
/// side and whose light the path guide does not learn.
inline constexpr uint8_t kMediumSide = 0xff;

/// Follows kSpecularChain across a bounce that was `specular` or not.
inline uint8_t ExtendSpecularChain(uint8_t flags, bool specular) {
    if (!specular) return uint8_t((flags & ~kSpecularChain) | kChainBroken);
    return (flags & kChainBroken) ? flags : uint8_t(flags | kSpecularChain);
}

/// The round of pass `pass` (a camera ray's sample index) in a render that learns in rounds of
/// doubling length after two of two passes, passes 0-1 | 2-3 | 4-7 | 8-15 | ... (path guiding,
/// GuideRounds::kDoublingPasses): the scheduler counts the rays in flight per round
/// (StreamScheduler::DrainRoundsBefore).
inline uint32_t RoundOfPass(uint32_t pass) {
    return pass < 2 ? 0 : uint32_t(std::bit_width(pass)) - 1;
}
/// The first pass of round `round`.
inline uint32_t FirstPassOfRound(uint32_t round) { return round == 0 ? 0 : 1u << round; }

struct RayRecord {
    Vec3f origin;
    float t_max = 0;      ///< end of the ray (infinity, or just short of a point light)
    Vec3f dir;            ///< unit length
    float t_enter = 0;    ///< start of the segment in the current brick's cell
    float t_exit = 0;     ///< end of the segment in the current brick's cell
    uint32_t pixel = 0;   ///< pixel index (y * width + x), or photon index
    uint32_t sample = 0;  ///< sample index within the pixel
    uint8_t depth = 0;    ///< scatterings so far (straight passes through thin glass do not count;
                          ///< render.max_depth is at most 255)
    /// The medium the ray travels in (RenderScene::MediumOf): kOutsideMedium, the air's, or the
    /// inside of the closed solid it entered last through its surface (MediumPast).
    uint8_t medium = kOutsideMedium;
    uint8_t kind = kPathRay;
    uint8_t flags = 0;
    uint16_t vertex =
        0;  ///< surfaces met so far, passes through thin glass included (keys the random numbers)
    uint8_t guide_side = 0;  ///< path rays: PathGuide::SideOf the last scattering vertex's
                             ///< surface; kSkyShadow rays: that of their own vertex
    /// The level of detail of the surface the ray starts on (0: full detail, or a ray from the
    /// camera or a light): up to level_reach, the ray keeps it (StreamScheduler::Route).
    uint8_t origin_level = 0;
    union {
        /// Path rays: the solid-angle pdf of the last BSDF sample (MIS against the sun and sky).
        float prev_pdf = 0;
        /// Sky shadow rays (kSkyShadow): what turns the contribution's average into the ray's
        /// estimate of the light its window brings (LightSampler::LearnFromSkyShadow).
        float window_estimate_scale;
    };
    float since_vertex =
        0;  ///< distance from the last scattering vertex to `origin` (passes through thin
            ///< glass move the origin along the ray; the sky's MIS needs the vertex)
    uint32_t guide_credit =
        0xffffffffu;  ///< shadow rays of guided paths: PathGuide::CreditKey of the path's
                      ///< previous vertex and direction (PathGuide::kNoCredit: none)
    union {
        /// Shadow rays of guided paths: the contribution's luminance times this is the credit
        /// (1 / (throughput at the vertex * pdf of the direction from the previous)).
        float guide_scale = 0;
        /// Path rays in a medium: the density's integral from the origin to t_enter, the flight
        /// so far (transport/medium_flight.h), carried from brick to brick.
        float flight_depth;
    };
    /// The ray's cone (Amanatides 1984; Akenine-Möller et al. 2019, "Improved shader and texture
    /// level of detail using ray cones"): its footprint is cone_width + cone_spread * t wide at t.
    /// It chooses the level of detail of each brick the ray crosses (level_choice.h).
    float cone_width = 0;
    float cone_spread = 0;
    /// How far along the ray it keeps origin_level in every brick it enters (LevelReach): past it,
    /// the copies of its surface at other levels lie behind it. 0: only in the brick it starts in.
    float level_reach = 0;
    SampledSpectrum
        beta;  ///< throughput; for shadow rays the contribution itself; for photons the power
    SampledWavelengths lambda;
};
// docs/render.md and docs/pager.md give this size (queue memory per ray in flight): change them
// with it.
static_assert(sizeof(RayRecord) == 128, "RayRecord's size is documented in docs/render.md");

}  // namespace nave::render
