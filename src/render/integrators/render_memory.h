#pragma once
// What a render holds beside bricks and ray queues, for `nave render --memory`'s plan
// (stream/memory_plan.h): the film, the light transport's state of its mode and a checkpoint being
// written. The plan adds these up without knowing what they are.

#include "src/render/scene/scene_config.h"
#include "src/render/stream/memory_plan.h"

namespace nave::render {

/// The memory of a render of `settings` at `width` x `height`: the film's, photon mode's visible
/// points and emitter learning or path mode's guide, and with `checkpoints` what writing one holds
/// (`aov`: the output has AOV channels, which a checkpoint holds too; `caustic_points`: photon
/// mode keeps a caustic point per pixel, UsesCausticPoints in transport/visible_points.h).
RenderStateBytes RenderStateMemory(const RenderSettings& settings, int width, int height, bool aov,
                                   bool checkpoints, bool caustic_points = false);

}  // namespace nave::render
