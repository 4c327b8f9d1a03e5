#pragma once
// Rendering with ray streams over bricks (the domain decomposition of the origin paper). Every ray
// in flight
// - camera path, continuation, shadow ray, photon - is a compact record waiting in the queue of the
// brick its next segment lies in. The scheduler repeatedly picks the brick with the most rays
// waiting, pins it through the BrickSource, and all threads trace that brick's batch inside the
// brick's cell; hits are shaded with the brick's own data and every spawned ray, or ray leaving the
// cell, is queued at the next brick along it. Nothing assumes that a brick not pinned is resident.
//
// Determinism: every random number of a ray is a hash of (seed, pixel, sample, depth, iteration),
// and the film sums in double, so the image does not depend on the number of bricks, the processing
// order or the thread count beyond double-precision summation order (relative 1e-12 on a pixel,
// bound tested) and float differences of hits found in different bricks (none in the tests: same
// triangles, same rays).

#include "src/core/status.h"
#include "src/render/film/film.h"
#include "src/render/integrators/render_session.h"
#include "src/render/integrators/render_stats.h"
#include "src/render/scene/scene.h"
#include "src/render/stream/brick_picker.h"
#include "src/render/stream/pager.h"
#include "src/render/stream/ray_exchange.h"

namespace nave::render {

/// Renders `scene` into `film` in the mode of scene.settings: Integrator::Create makes the mode's
/// integrator and this driver renders its rounds the same way for every mode (resume, progress,
/// the stopping rule, checkpoints), then fills `stats`. `film` must match the camera's
/// resolution. Thread count: scene.settings.threads (0: all cores). `picker` empty: the pager's
/// choice (the fullest resident brick first). `paging` null: in-core with the default tunables
/// (bricks stay once loaded, and are loaded in the background while the workers trace); else bricks
/// are paged under paging->brick_budget_bytes (pager.h; kUnlimitedBrickBudget is in-core), and an
/// impossible budget is refused before anything is traced. `session` (null: one run from the start)
/// continues from a checkpoint, writes checkpoints and may end the run early (render_session.h).
/// `ranks` (null: one process) renders as one of the processes of a distributed render
/// (docs/distributed.md): this one traces the rays of its bricks, and every process ends with the
/// whole image in `film`.
Status RenderStreams(const RenderScene& scene, Film* film, RenderStats* stats,
                     BrickPicker picker = {}, const PagerOptions* paging = nullptr,
                     const SessionOptions* session = nullptr, RankGroup* ranks = nullptr);

}  // namespace nave::render
