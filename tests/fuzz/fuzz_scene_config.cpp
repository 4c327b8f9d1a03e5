// The scene config parser (TOML): any text gives a config or an error, never an exception that
// escapes, a crash or a sanitizer report.

#include "fuzz_file.h"
#include "src/render/scene/scene_config.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    (void)nave::render::ParseSceneConfig(nave::fuzz::AsView(data, size), "fuzz.toml");
    return 0;
}
