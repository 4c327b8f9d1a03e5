#pragma once
// Which medium a ray travels in, as a ray carries it (RayRecord::medium): the air's, or the inside
// of a closed solid (RenderScene::MediumOf).

#include <cstdint>

namespace nave::render {

/// The medium of a ray outside every closed solid: in the air, and its [medium] if there is one.
/// Camera rays and photons start there.
inline constexpr uint8_t kOutsideMedium = 0;
/// The inside of a solid dielectric whose material has no medium table (clear glass): no medium
/// flies there, and the air's does not reach in.
inline constexpr uint8_t kClearSolid = 1;

}  // namespace nave::render
