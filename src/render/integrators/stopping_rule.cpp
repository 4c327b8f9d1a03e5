#include "src/render/integrators/stopping_rule.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "src/core/progress.h"

namespace nave::render {

StoppingRule::StoppingRule(const RenderSettings& settings, ProgressBar* progress,
                           double elapsed_before_s)
    : time_limit_s_(settings.time_limit_s),
      noise_target_(settings.noise_target),
      progress_(progress),
      start_(std::chrono::steady_clock::now()),
      elapsed_before_s_(elapsed_before_s) {
    // Under a time limit the bar fills with the time, and shows the time left to the limit.
    if (progress_ != nullptr && time_limit_s_ > 0) {
        progress_->SetDeadline(std::max(1e-3, time_limit_s_ - elapsed_before_s_));
    }
}

double StoppingRule::Elapsed() const {
    return elapsed_before_s_ +
           std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

bool StoppingRule::ShouldStop(const std::function<double()>& noise) {
    const double elapsed = Elapsed();
    if (time_limit_s_ > 0 && elapsed >= time_limit_s_) return true;
    // Under a time limit the noise reached so far is worth seeing too: the image's quality is
    // what the limit buys.
    const bool show_noise = progress_ != nullptr && time_limit_s_ > 0;
    if (noise_target_ <= 0 && !show_noise) return false;
    const double relmse = noise();
    if (!std::isfinite(relmse)) return false;
    if (noise_target_ <= 0) {
        progress_->SetNote(fmt::format("noise {:.3g}", relmse));
        return false;
    }
    if (relmse <= noise_target_) return true;
    if (progress_ != nullptr) {
        // The relMSE of an unbiased estimate falls as 1 / (samples taken), so as 1 / time.
        progress_->SetNote(fmt::format("noise {:.3g}, target {:.3g} in ~{}", relmse, noise_target_,
                                       FormatDuration(elapsed * (relmse / noise_target_ - 1))));
    }
    return false;
}

}  // namespace nave::render
