#include "src/render/integrators/render_memory.h"

#include "src/render/film/film.h"
#include "src/render/integrators/render_session.h"
#include "src/render/transport/path_guide.h"
#include "src/render/transport/photon_emitters.h"
#include "src/render/transport/sky_windows.h"
#include "src/render/transport/visible_points.h"

namespace nave::render {

RenderStateBytes RenderStateMemory(const RenderSettings& settings, int width, int height, bool aov,
                                   bool checkpoints, bool caustic_points) {
    const uint64_t pixels = uint64_t(width) * uint64_t(height);
    RenderStateBytes state;
    state.film = Film::MemoryBytes(width, height);
    if (settings.mode == RenderSettings::Mode::kPhoton) {
        // The visible points and what the photon emitters learn from.
        state.transport = VisiblePoints::MemoryBytes(pixels, caustic_points) +
                          PhotonEmitters::LearningBytes(settings.photons_per_iteration);
        // The windows the sky's photons teach its next-event estimation.
        if (settings.LearnsSkyWindows()) state.transport += SkyWindows::kMemoryReserveBytes;
        // Final gathering's guide, learned from the photons.
        if (settings.final_gather)
            state.transport +=
                PathGuide::MemoryBytes(kGuideCoarseCellsLongAxis, kGatherGuideMaxCells);
    } else if (settings.path_guiding) {
        state.transport = PathGuide::MemoryBytes(kGuideCoarseCellsLongAxis, kGuideMaxCells,
                                                 GuideRounds::kDoublingPasses);
    }
    // Writing a checkpoint holds the film's and the guide's state beside them.
    state.checkpoint = checkpoints ? CheckpointMemoryBytes(settings, width, height, aov) : 0;
    return state;
}

}  // namespace nave::render
