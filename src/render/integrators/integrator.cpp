#include "src/render/integrators/integrator.h"

#include "src/render/integrators/path_integrator.h"
#include "src/render/integrators/sppm_integrator.h"

namespace nave::render {

StatusOr<std::unique_ptr<Integrator>> Integrator::Create(const RenderScene& scene, Film* film,
                                                         StreamScheduler& scheduler) {
    // Between surfaces only a medium acts on a ray: without one, a brick crossed in its air may be
    // passed over.
    if (!scene.HasMedia()) scheduler.SkipBricksCrossedInAir();
    switch (scene.settings.mode) {
        case RenderSettings::Mode::kPath: {
            NAVE_ASSIGN_OR_RETURN(std::unique_ptr<PathIntegrator> path,
                                  PathIntegrator::Create(scene, film, scheduler));
            return std::unique_ptr<Integrator>(std::move(path));
        }
        case RenderSettings::Mode::kPhoton: {
            NAVE_ASSIGN_OR_RETURN(std::unique_ptr<SppmIntegrator> sppm,
                                  SppmIntegrator::Create(scene, film, scheduler));
            return std::unique_ptr<Integrator>(std::move(sppm));
        }
    }
    return InvalidArgumentError("unknown render mode {}", int(scene.settings.mode));
}

}  // namespace nave::render
