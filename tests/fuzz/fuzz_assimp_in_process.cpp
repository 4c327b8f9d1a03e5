// Assimp in this process, on OFF files: finds inputs on which Assimp itself aborts or crashes, and
// exercises nave's conversion of what it returns (the scene to ImportedModel, the byte stream, the
// triangle source). An abort inside Assimp is expected here (Assimp 5.2's ai_assert); nave contains
// it by running Assimp in a child process, which fuzz_assimp_isolated checks. docs/fuzzing.md says
// how to run this target past those crashes and replay them through the isolated path.

#include "drain.h"
#include "fuzz_file.h"
#include "preprocess/import/assimp_scene.h"
#include "preprocess/import/model_wire.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace nave::preprocess;
    const auto path = nave::fuzz::WriteInput("fuzz.off", nave::fuzz::AsView(data, size));
    nave::StatusOr<ImportedModel> model = ReadWithAssimpInProcess(path);
    if (!model.ok()) return 0;
    nave::StatusOr<ImportedModel> back =
        DecodeImportedModel(EncodeImportedModel(*model), "fuzz.off");
    if (!back.ok()) std::abort();  // what one side encodes the other must decode
    nave::fuzz::Drain(std::unique_ptr<TriangleSource>(
        new IndexedMeshSource("fuzz.off", "unknown", std::move(back->meshes),
                              std::move(back->materials), ImportWarnings())));
    return 0;
}
