#pragma once
// The scene of the pager tests (a floor, a grid of balls and a lamp under sun and sky), shared by
// the in-process pager tests and the `nave render --memory` ones: its material names and its
// config, a format string whose one field is the render mode.

#include <string>
#include <vector>

#include "render_test_util.h"

namespace nave::render {

inline const std::vector<std::string> kNames = {"floor", "ball", "lamp"};
inline const std::string kBallGrid = R"(
[camera]
position = [7, 6, 5]
look_at = [0, 0, 0.5]
fov_deg = 50
resolution = [32, 24]
)" + testing::SunSkyFloorAndBall() +
                                     R"(
[materials.lamp]
reflectance = 0.5
emission = 2.0
[render]
mode = "{}"
spp = 4
iterations = 2
photons_per_iteration = 20000
seed = 5
)";

}  // namespace nave::render
