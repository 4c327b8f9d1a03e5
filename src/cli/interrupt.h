#pragma once
// SIGINT and SIGTERM during a render that writes checkpoints: the first asks the render to stop at
// its next pass or iteration, once the checkpoint is written; a second ends the process at once.

#include <atomic>

namespace nave::cli {

/// Installs the handlers (once) and returns the flag they set.
const std::atomic<bool>* InstallRenderInterruptHandlers();

}  // namespace nave::cli
