#pragma once
// When a progressive render stops: after its last pass (path mode) or iteration (photon mode), once
// render.time_limit_s has passed, or once its own noise estimate reaches render.noise_target.

#include <chrono>
#include <functional>

#include "src/render/scene/scene_config.h"

namespace nave {
class ProgressBar;
}

namespace nave::render {

class StoppingRule {
  public:
    /// The rule of `settings`; `progress` (may be null) shows the noise estimate as it goes and,
    /// under a time limit, fills with the time and shows the time left.
    /// `elapsed_before_s`: seconds the render spent in earlier runs (resumed from a checkpoint),
    /// which count toward the time limit.
    StoppingRule(const RenderSettings& settings, ProgressBar* progress,
                 double elapsed_before_s = 0);

    /// Whether to stop after a pass or iteration. `noise()` gives the render's estimated relMSE now
    /// (NaN while it cannot be estimated); it is called only when a noise target is set.
    bool ShouldStop(const std::function<double()>& noise);

    /// Seconds of rendering so far, earlier runs included.
    double Elapsed() const;

  private:
    double time_limit_s_;
    double noise_target_;
    ProgressBar* progress_;
    std::chrono::steady_clock::time_point start_;
    double elapsed_before_s_;
};

}  // namespace nave::render
